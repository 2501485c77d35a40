//! Print a map file as a Moving AI `.map` grid, read the way `ohaca plan` reads it (ROS
//! `map_server` YAML: the file's thresholds, unknown cells blocked, no inflation, native
//! resolution). `maps/depot.map` was made with
//!
//! ```sh
//! cargo run -q -p ohaca-host --target host-tuple --example to_movingai -- \
//!     host/assets/ros/depot.yaml > maps/depot.map
//! ```

use std::process::ExitCode;

fn main() -> ExitCode {
    let Some(path) = std::env::args().nth(1) else {
        eprintln!("usage: to_movingai MAP");
        return ExitCode::from(2);
    };
    match ohaca_host::Map::load(&path) {
        Ok(m) => {
            print!("{}", m.to_moving_ai());
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {path}: {e}");
            ExitCode::from(2)
        }
    }
}
