//! Every way a call on the link fails ([`LinkError`]), the frames nobody waited for ([`Stray`]),
//! and the io errors that mean a closed peer or "nothing yet".

use super::*;

/// A reply nobody was waiting for.
#[derive(Clone, Debug, PartialEq)]
pub enum Stray {
    /// A reply whose id is not in flight (0: the device could not read some frame).
    Reply {
        /// Its id.
        id: u32,
        /// What it said.
        response: Response,
    },
}

impl std::fmt::Display for Stray {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Stray::Reply {
                id,
                response: Response::Error(e),
            } => write!(f, "reply {id}: error {} ({e})", e.code.code()),
            Stray::Reply { id, response } => write!(f, "reply {id}: {}", response.kind()),
        }
    }
}

/// Why a call failed.
#[derive(Debug, thiserror::Error)]
pub enum LinkError {
    /// The transport could not be opened.
    #[error("cannot open {target}: {source}")]
    Open {
        /// The address or device path.
        target: String,
        /// What the operating system said.
        #[source]
        source: io::Error,
    },
    /// No reply in time.
    #[error("no reply to {request} (request {id}) within {}", secs(*.timeout))]
    Timeout {
        /// The request waited for.
        request: &'static str,
        /// Its id.
        id: u32,
        /// How long the call waited.
        timeout: Duration,
    },
    /// The device (or QEMU) closed the connection.
    #[error("the device closed the connection")]
    Disconnected,
    /// Reading or writing failed.
    #[error("i/o error on the link: {0}")]
    Io(#[source] io::Error),
    /// The device answered with an error reply.
    #[error("device refused {request}: {error} (error code {})", .error.code.code())]
    Device {
        /// The request it refused.
        request: &'static str,
        /// Its error reply.
        error: ErrorReply,
    },
    /// A frame from the device did not decode (corrupted on the line, or a different protocol).
    #[error("undecodable frame from the device: {0}")]
    Decode(DecodeError),
    /// The device answered with the wrong kind of reply.
    #[error("device answered {request} with {got}")]
    Unexpected {
        /// The request.
        request: &'static str,
        /// The reply's kind.
        got: &'static str,
    },
    /// A request could not be encoded (over the protocol's limits).
    #[error("cannot encode {request}: {error}")]
    Encode {
        /// The request.
        request: &'static str,
        /// Why.
        error: EncodeError,
    },
    /// The device speaks another protocol version.
    #[error(
        "the device speaks protocol version {device}, this tool version {host}: \
         rebuild the firmware or the tool from the same sources"
    )]
    Version {
        /// The device's version.
        device: u16,
        /// [`VERSION`].
        host: u16,
    },
    /// The device sent a path that cannot be followed.
    #[error("bad path from the device: {0}")]
    BadPath(String),
}

impl LinkError {
    /// The device's error code, for [`LinkError::Device`].
    pub fn code(&self) -> Option<ErrorCode> {
        match self {
            LinkError::Device { error, .. } => Some(error.code),
            _ => None,
        }
    }
}

/// `10 s`, `0.5 s`.
pub(super) fn secs(d: Duration) -> String {
    format!("{} s", d.as_secs_f64())
}

/// An io error that means the peer went away.
pub(super) fn is_disconnect(e: &io::Error) -> bool {
    use io::ErrorKind::*;
    // EIO: the other side of a pty was closed (QEMU exited).
    matches!(
        e.kind(),
        BrokenPipe | ConnectionReset | ConnectionAborted | UnexpectedEof | NotConnected
    ) || (cfg!(unix) && e.raw_os_error() == Some(5))
}

/// An io error that means "nothing yet".
pub(super) fn is_timeout(e: &io::Error) -> bool {
    matches!(
        e.kind(),
        io::ErrorKind::WouldBlock | io::ErrorKind::TimedOut | io::ErrorKind::Interrupted
    )
}

pub(super) fn unexpected(request: &'static str, got: Response) -> LinkError {
    match got {
        Response::Error(error) => LinkError::Device { request, error },
        other => LinkError::Unexpected {
            request,
            got: other.kind(),
        },
    }
}
