//! The byte stream to the device: [`Transport`] (reads and writes bounded in time) over a TCP
//! socket (QEMU's UART) or a serial port ([`Serial`]).

use super::*;

/// A byte stream to the device whose reads and writes can be bounded in time.
pub trait Transport: Read + Write {
    /// Make every later `read` and `write` give up (with `TimedOut` or `WouldBlock`) after
    /// `timeout`.
    fn set_io_timeout(&mut self, timeout: Duration) -> io::Result<()>;
}

impl Transport for TcpStream {
    fn set_io_timeout(&mut self, timeout: Duration) -> io::Result<()> {
        let t = Some(timeout.max(Duration::from_millis(1)));
        self.set_read_timeout(t)?;
        self.set_write_timeout(t)
    }
}

impl<T: Transport + ?Sized> Transport for Box<T> {
    fn set_io_timeout(&mut self, timeout: Duration) -> io::Result<()> {
        (**self).set_io_timeout(timeout)
    }
}

/// A serial port (a USB-serial adapter, a pty) as a [`Transport`].
pub struct Serial(pub Box<dyn serialport::SerialPort>);

impl Read for Serial {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        self.0.read(buf)
    }
}

impl Write for Serial {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        self.0.write(buf)
    }
    fn flush(&mut self) -> io::Result<()> {
        self.0.flush()
    }
}

impl Transport for Serial {
    fn set_io_timeout(&mut self, timeout: Duration) -> io::Result<()> {
        self.0
            .set_timeout(timeout.max(Duration::from_millis(1)))
            .map_err(io::Error::from)
    }
}
