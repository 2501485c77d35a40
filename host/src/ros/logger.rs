//! The log of `ohaca ros`: one line per event on stderr, `HH:MM:SS.mmm LEVEL message` (UTC),
//! through the `log` facade that ros2-client and RustDDS also use. Our own lines from `level`
//! up; the DDS libraries' only errors (RustDDS warns about every locator it skips; `--log-level
//! debug` shows theirs too).

use std::io::Write;

use log::{Level, LevelFilter, Log, Metadata, Record};

struct Stderr {
    level: Level,
}

impl Log for Stderr {
    fn enabled(&self, m: &Metadata<'_>) -> bool {
        let ours = m.target().starts_with("ohaca");
        m.level()
            <= if ours || self.level >= Level::Debug {
                self.level
            } else {
                Level::Error
            }
    }

    fn log(&self, r: &Record<'_>) {
        if !self.enabled(r.metadata()) {
            return;
        }
        let t = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .unwrap_or_default();
        let (s, ms) = (t.as_secs() % 86_400, t.subsec_millis());
        let line = format!(
            "{:02}:{:02}:{:02}.{ms:03} {:<5} {}\n",
            s / 3600,
            s / 60 % 60,
            s % 60,
            r.level(),
            r.args()
        );
        let _ = std::io::stderr().lock().write_all(line.as_bytes());
    }

    fn flush(&self) {}
}

/// Install the logger (once; later calls change nothing).
pub fn init(level: Level) {
    let logger = Box::new(Stderr { level });
    if log::set_boxed_logger(logger).is_ok() {
        log::set_max_level(LevelFilter::Trace);
    }
}
