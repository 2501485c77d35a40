//! Print a map file as a Moving AI `.map` grid, read the way `ohaca plan` reads it (ROS
//! `map_server` YAML: the file's thresholds, unknown cells blocked, native resolution), with no
//! inflation unless `--inflate RADIUS` is given (metres for maps with a resolution, cells
//! otherwise: `ohaca plan --inflate`'s rule, `ohaca_host::map::prepare`). `maps/depot.map` and
//! `maps/depot-r20.map` (0.2 m, the robot's radius) were made with
//!
//! ```sh
//! cargo run -q -p ohaca-host --target host-tuple --example to_movingai -- \
//!     host/assets/ros/depot.yaml > maps/depot.map
//! cargo run -q -p ohaca-host --target host-tuple --example to_movingai -- \
//!     host/assets/ros/depot.yaml --inflate 0.2 > maps/depot-r20.map
//! ```

use std::path::Path;
use std::process::ExitCode;

use ohaca_host::map::{prepare, Unknown};

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (path, inflate) = match args.as_slice() {
        [p] => (p, None),
        [p, flag, r] if flag == "--inflate" => match r.parse::<f64>() {
            Ok(r) if r.is_finite() && r >= 0.0 => (p, Some(r)),
            _ => {
                eprintln!("error: --inflate must be a length >= 0, not {r}");
                return ExitCode::from(2);
            }
        },
        _ => {
            eprintln!("usage: to_movingai MAP [--inflate RADIUS]");
            return ExitCode::from(2);
        }
    };
    match prepare(Path::new(path), Unknown::Blocked, inflate, None) {
        Ok((m, _)) => {
            print!("{}", m.to_moving_ai());
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {path}: {e}");
            ExitCode::from(2)
        }
    }
}
