//! Maps: every file format the tool reads, one [`load`], and the preparation for a robot and a
//! device ([`prepare`], [`fit`]), into one owned [`Map`] (with its [`MapFrame`] when the format
//! gives a resolution).
//!
//! | extension | format | module | positions |
//! | --- | --- | --- | --- |
//! | `.yaml`, `.yml` | ROS `map_server` YAML + its PGM/PNG image | [`ros`] | cells, or metres |
//! | `.png`, `.pgm`, `.pnm`, `.ppm` (or a PNG signature) | plain image, dark = blocked | [`image`] | cells |
//! | anything else | Moving AI `.map` or text grid (told apart by content, [`Format::detect`]) | [`text`] | cells |
//!
//! Order of preparation ([`prepare`]): unknown cells are resolved while loading, then the
//! inflation on the file's own cells, then the resampling to a cell size.
//!
//! Modules, each importing only those listed before it: [`bitmap`] (the [`Map`] type),
//! [`error`], [`metric`] (cells <-> metres), [`text`], [`image`], [`ros`], [`ops`] (inflation,
//! resampling), [`fit`] (cropping and resampling to a device's capacity); this file detects the format, loads and prepares.

use std::path::Path;

pub mod bitmap;
pub mod error;
pub mod fit;
pub mod image;
pub mod metric;
pub mod ops;
pub mod ros;
pub mod text;

pub use bitmap::{Map, MAX_SIDE};
pub use error::{MapError, Problem};
pub use fit::{fit, fits, free_bounds, FitError, Fitted};
pub use image::{decode_image, image_map, load_image, read_image};
pub use metric::{round_um, MapFrame};
pub use ops::{inflate, resample, resample_frame, squared_distances, ResampleError};
pub use ros::{load_ros, ros_map, Mode, Occupancy, RosMeta, Unknown};
pub use text::Format;

/// Which loader a file asks for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    Ros,
    Image,
    Text,
}

/// The loader for `path`: by extension, else a PNG signature, else a text format.
fn kind(path: &Path) -> Kind {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("yaml" | "yml") => Kind::Ros,
        Some("png" | "pgm" | "pnm" | "ppm") => Kind::Image,
        _ => {
            // A PNG under another name.
            let mut head = [0u8; 8];
            let png = std::fs::File::open(path)
                .and_then(|mut f| std::io::Read::read_exact(&mut f, &mut head))
                .is_ok()
                && head == *b"\x89PNG\r\n\x1a\n";
            if png {
                Kind::Image
            } else {
                Kind::Text
            }
        }
    }
}

/// Load a map file of any supported format (see the module docs), with its metric frame if it
/// has one. `unknown` says what ROS's unknown cells become.
pub fn load(path: &Path, unknown: Unknown) -> Result<(Map, Option<MapFrame>), MapError> {
    match kind(path) {
        Kind::Ros => load_ros(path, unknown).map(|(m, f)| (m, Some(f))),
        Kind::Image => load_image(path).map(|m| (m, None)),
        Kind::Text => Ok((Map::read_text(path)?, None)),
    }
}

impl Map {
    /// Load a map file of any supported format ([`load`]; ROS's unknown cells blocked), as
    /// cells only.
    pub fn load(path: impl AsRef<Path>) -> Result<Map, MapError> {
        load(path.as_ref(), Unknown::Blocked).map(|(m, _)| m)
    }
}

/// Load a map file ([`load`]) and prepare it for the robot: unknown cells resolved while
/// loading, then `inflate_by` (a radius) on the file's own cells, then `cell` resampling (a cell
/// size); both in metres for maps with a resolution, in cells otherwise. The metric frame follows
/// the resampling.
pub fn prepare(
    path: &Path,
    unknown: Unknown,
    inflate_by: Option<f64>,
    cell: Option<f64>,
) -> Result<(Map, Option<MapFrame>), MapError> {
    let (mut map, mut metric) = load(path, unknown)?;
    let unit = metric.map_or(1.0, |f| f.resolution);
    if let Some(r) = inflate_by {
        map = inflate(&map, r / unit);
    }
    if let Some(size) = cell {
        let factor = size / unit;
        let coarse = resample(&map, factor, metric.is_some()).map_err(|e| MapError::File {
            path: path.display().to_string(),
            problem: format!(
                "--cell {size}: {e}{}",
                metric.map_or_else(String::new, |f| format!(
                    "; the map's resolution is {} m",
                    f.cell_size_m()
                ))
            ),
        })?;
        metric = metric.map(|f| resample_frame(&f, &coarse, factor));
        map = coarse;
    }
    Ok((map, metric))
}
