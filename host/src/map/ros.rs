//! Real robot maps: ROS `map_server` maps, a YAML file and its PGM or PNG image.
//!
//! ## ROS `map_server` YAML
//! ```yaml
//! image: lab.pgm            # relative to the YAML file's folder (or absolute)
//! resolution: 0.05          # metres per pixel, > 0
//! origin: [-10.0, -10.0, 0.0]   # x, y, yaw of the lower-left pixel (yaw optional, radians)
//! negate: 0                 # optional, 0 or 1 (also true/false)
//! occupied_thresh: 0.65     # optional, in [0, 1]
//! free_thresh: 0.196        # optional, in [0, 1], at most occupied_thresh
//! mode: trinary             # optional: trinary (default), scale or raw
//! ```
//! Other keys are ignored. Each pixel's value `v` (0-255; the mean of R, G, B for colour images)
//! becomes an occupancy probability `p = (255 - v) / 255`, or `v / 255` with `negate`; then
//! `p > occupied_thresh` is **blocked**, `p < free_thresh` is **free**, anything else is
//! **unknown**, as in ROS. In `scale` mode a pixel that is not fully opaque is unknown too (ROS's
//! rule); in `raw` mode the value itself is the occupancy in percent (`0..=100`, compared with the
//! thresholds times 100) and values above 100 are unknown. Unknown cells become blocked unless
//! [`Unknown::Free`] is asked for (`--unknown free`). The standard `map_saver` output (254 free,
//! 0 occupied, 205 unknown) is read as intended.
//!
//! Image row 0 is the **top** of the map (the planner's `y = 0`), while ROS's origin is the
//! **lower-left** pixel: [`MapFrame`] does that flip.

use std::path::{Path, PathBuf};

use image::RgbaImage;
use serde_norway::Value;

use super::bitmap::Map;
use super::error::MapError;
use super::image::{grey, read_image, sides};
use super::metric::MapFrame;

/// What to do with cells whose occupancy is between the thresholds (ROS's "unknown", usually the
/// unexplored area).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum Unknown {
    /// Unknown cells are obstacles (the safe default).
    #[default]
    Blocked,
    /// Unknown cells are free.
    Free,
}

/// How pixel values are read (ROS's `mode`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    /// Occupied, free or unknown by the thresholds.
    Trinary,
    /// As trinary, and a pixel that is not fully opaque is unknown.
    Scale,
    /// The value is the occupancy in percent; above 100 is unknown.
    Raw,
}

/// The fields of a `map_server` YAML file.
#[derive(Clone, Debug, PartialEq)]
pub struct RosMeta {
    /// The image file, resolved against the YAML file's folder.
    pub image: PathBuf,
    /// Metres per pixel.
    pub resolution: f64,
    /// x, y, yaw of the lower-left pixel.
    pub origin: [f64; 3],
    /// Dark means free instead of occupied.
    pub negate: bool,
    /// Occupancy above this is blocked.
    pub occupied_thresh: f64,
    /// Occupancy below this is free.
    pub free_thresh: f64,
    /// How values are read.
    pub mode: Mode,
}

/// One pixel's class.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Occupancy {
    /// Free space.
    Free,
    /// An obstacle.
    Occupied,
    /// Neither (unexplored).
    Unknown,
}

/// A short description of a YAML value for error messages.
fn show(v: &Value) -> String {
    match v {
        Value::Null => "nothing".to_string(),
        Value::Bool(b) => format!("`{b}`"),
        Value::Number(n) => format!("`{n}`"),
        Value::String(s) => format!("`{s}`"),
        Value::Sequence(s) => format!("a list of {}", s.len()),
        Value::Mapping(_) => "a mapping".to_string(),
        Value::Tagged(t) => format!("a tagged value `{}`", t.tag),
    }
}

fn number(v: &Value) -> Option<f64> {
    v.as_f64().filter(|f| f.is_finite())
}

/// What is wrong with a `map_server` YAML file (the caller adds the file's name).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum YamlError {
    /// Not YAML at all (the parser's words).
    #[error("not valid YAML: {0}")]
    Syntax(String),
    /// YAML, but not a mapping of fields.
    #[error("expected a mapping of fields (image, resolution, origin, ...), found {0}")]
    NotAMapping(String),
    /// A required field is missing.
    #[error("missing field `{field}` ({what})")]
    Missing {
        /// The field.
        field: &'static str,
        /// What it holds.
        what: &'static str,
    },
    /// A field has a value of the wrong kind or range.
    #[error("field `{field}` must be {want}, found {found}")]
    Field {
        /// The field.
        field: String,
        /// What it must be.
        want: &'static str,
        /// What it is.
        found: String,
    },
    /// The thresholds are the wrong way round.
    #[error("free_thresh {free} is greater than occupied_thresh {occupied}")]
    Thresholds {
        /// `free_thresh`.
        free: f64,
        /// `occupied_thresh`.
        occupied: f64,
    },
}

impl RosMeta {
    /// Parse the YAML text of a `map_server` map; `yaml` is the file's path (for the image's
    /// folder). The error is the problem only (the caller adds the file name).
    pub fn parse(text: &str, yaml: &Path) -> Result<RosMeta, YamlError> {
        let doc: Value =
            serde_norway::from_str(text).map_err(|e| YamlError::Syntax(e.to_string()))?;
        let Some(fields) = doc.as_mapping() else {
            return Err(YamlError::NotAMapping(show(&doc)));
        };
        let field = |name: &str| fields.get(name);
        let bad = |name: &str, want: &'static str, v: &Value| YamlError::Field {
            field: name.to_string(),
            want,
            found: show(v),
        };

        let image = match field("image") {
            None => {
                return Err(YamlError::Missing {
                    field: "image",
                    what: "the PGM or PNG file",
                })
            }
            Some(v) => match v.as_str() {
                Some(s) if !s.trim().is_empty() => s.trim().to_string(),
                _ => return Err(bad("image", "a file name", v)),
            },
        };
        let image_path = Path::new(&image);
        let image = if image_path.is_absolute() {
            image_path.to_path_buf()
        } else {
            yaml.parent()
                .map_or_else(|| image_path.to_path_buf(), |d| d.join(image_path))
        };

        let resolution = match field("resolution") {
            None => {
                return Err(YamlError::Missing {
                    field: "resolution",
                    what: "metres per pixel",
                })
            }
            Some(v) => match number(v) {
                Some(r) if r > 0.0 => r,
                _ => return Err(bad("resolution", "a number greater than 0", v)),
            },
        };

        let origin = match field("origin") {
            None => {
                return Err(YamlError::Missing {
                    field: "origin",
                    what: "[x, y, yaw] of the lower-left pixel",
                })
            }
            Some(v) => {
                let want = "a list [x, y, yaw] of numbers";
                let seq = v.as_sequence().ok_or_else(|| bad("origin", want, v))?;
                let nums: Option<Vec<f64>> = seq.iter().map(number).collect();
                match nums.as_deref() {
                    Some(&[x, y]) => [x, y, 0.0],
                    Some(&[x, y, yaw]) => [x, y, yaw],
                    _ => return Err(bad("origin", want, v)),
                }
            }
        };

        let negate = match field("negate") {
            None => false,
            Some(v) => match (v.as_i64(), v.as_bool()) {
                (Some(0), _) | (_, Some(false)) => false,
                (Some(1), _) | (_, Some(true)) => true,
                _ => return Err(bad("negate", "0 or 1", v)),
            },
        };

        let thresh = |name: &str, default: f64| -> Result<f64, YamlError> {
            match field(name) {
                None => Ok(default),
                Some(v) => match number(v) {
                    Some(t) if (0.0..=1.0).contains(&t) => Ok(t),
                    _ => Err(bad(name, "a number in [0, 1]", v)),
                },
            }
        };
        let occupied_thresh = thresh("occupied_thresh", 0.65)?;
        let free_thresh = thresh("free_thresh", 0.196)?;
        if free_thresh > occupied_thresh {
            return Err(YamlError::Thresholds {
                free: free_thresh,
                occupied: occupied_thresh,
            });
        }

        let mode = match field("mode") {
            None => Mode::Trinary,
            Some(v) => match v.as_str().map(str::trim) {
                Some("trinary") => Mode::Trinary,
                Some("scale") => Mode::Scale,
                Some("raw") => Mode::Raw,
                _ => return Err(bad("mode", "trinary, scale or raw", v)),
            },
        };

        Ok(RosMeta {
            image,
            resolution,
            origin,
            negate,
            occupied_thresh,
            free_thresh,
            mode,
        })
    }

    /// The class of a pixel with colour mean `value` (0-255) and opacity `alpha` (0-255).
    pub fn classify(&self, value: f64, alpha: u8) -> Occupancy {
        let v = if self.negate { 255.0 - value } else { value };
        let p = match self.mode {
            Mode::Raw => {
                let pct = v.round();
                if pct > 100.0 {
                    return Occupancy::Unknown;
                }
                pct / 100.0
            }
            Mode::Trinary | Mode::Scale => (255.0 - v) / 255.0,
        };
        if p > self.occupied_thresh {
            Occupancy::Occupied
        } else if p < self.free_thresh {
            if self.mode == Mode::Scale && alpha < 255 {
                Occupancy::Unknown
            } else {
                Occupancy::Free
            }
        } else {
            Occupancy::Unknown
        }
    }
}

/// Load a ROS `map_server` map: the YAML file at `yaml` and the image it names. Unknown cells
/// follow `unknown`.
pub fn load_ros(yaml: &Path, unknown: Unknown) -> Result<(Map, MapFrame), MapError> {
    let name = yaml.display().to_string();
    let err = |problem: String| MapError::File {
        path: name.clone(),
        problem,
    };
    let text =
        std::fs::read_to_string(yaml).map_err(|e| err(format!("cannot read the file: {e}")))?;
    let meta = RosMeta::parse(&text, yaml).map_err(|e| err(e.to_string()))?;
    if !meta.image.exists() {
        return Err(err(format!(
            "image `{}` does not exist",
            meta.image.display()
        )));
    }
    let img = read_image(&meta.image)?;
    Ok(ros_map(&meta, &img, unknown))
}

/// The map and metric frame of a ROS `map_server` map from its parsed YAML and its decoded image (what
/// [`load_ros`] does once the files are read). Unknown cells follow `unknown`.
pub fn ros_map(meta: &RosMeta, img: &RgbaImage, unknown: Unknown) -> (Map, MapFrame) {
    let (w, h) = sides(img);
    let map = Map::from_fn(w, h, |x, y| {
        let px = img.get_pixel(u32::from(x), u32::from(y));
        match meta.classify(grey(px), px.0[3]) {
            Occupancy::Occupied => true,
            Occupancy::Free => false,
            Occupancy::Unknown => unknown == Unknown::Blocked,
        }
    });
    let metric = MapFrame {
        resolution: meta.resolution,
        origin: [meta.origin[0], meta.origin[1]],
        yaw: meta.origin[2],
        width: w,
        height: h,
    };
    (map, metric)
}

#[cfg(test)]
mod tests {
    use super::super::image::decode_image;
    use super::*;

    fn meta(text: &str) -> Result<RosMeta, YamlError> {
        RosMeta::parse(text, Path::new("/maps/lab.yaml"))
    }

    const OK: &str = "image: lab.pgm\nresolution: 0.05\norigin: [-1.0, 2.0, 0.0]\n";

    #[test]
    fn defaults_and_paths() {
        let m = meta(OK).unwrap();
        assert_eq!(m.image, Path::new("/maps/lab.pgm"));
        assert_eq!(m.resolution, 0.05);
        assert_eq!(m.origin, [-1.0, 2.0, 0.0]);
        assert!(!m.negate);
        assert_eq!((m.occupied_thresh, m.free_thresh), (0.65, 0.196));
        assert_eq!(m.mode, Mode::Trinary);
        let m = meta(
            "image: /abs/x.png\nresolution: 1\norigin: [0, 0]\nnegate: 1\nmode: raw\nname: lab\n",
        )
        .unwrap();
        assert_eq!(m.image, Path::new("/abs/x.png"));
        assert!(m.negate);
        assert_eq!(m.origin, [0.0, 0.0, 0.0]);
        assert_eq!(m.mode, Mode::Raw);
        assert!(meta(&format!("{OK}negate: true\n")).unwrap().negate);
    }

    #[test]
    fn field_errors() {
        let cases = [
            ("resolution: 1\norigin: [0,0,0]\n", "missing field `image`"),
            (
                "image: a.pgm\norigin: [0,0,0]\n",
                "missing field `resolution`",
            ),
            ("image: a.pgm\nresolution: 1\n", "missing field `origin`"),
            (
                "image: a.pgm\nresolution: 0\norigin: [0,0,0]\n",
                "field `resolution` must be a number greater than 0, found `0`",
            ),
            (
                "image: a.pgm\nresolution: -0.05\norigin: [0,0,0]\n",
                "field `resolution` must be a number greater than 0, found `-0.05`",
            ),
            (
                "image: a.pgm\nresolution: abc\norigin: [0,0,0]\n",
                "field `resolution` must be a number greater than 0, found `abc`",
            ),
            (
                "image: a.pgm\nresolution: .nan\norigin: [0,0,0]\n",
                "field `resolution` must be a number greater than 0",
            ),
            (
                "image: a.pgm\nresolution: 1\norigin: [0, x, 0]\n",
                "field `origin` must be a list [x, y, yaw] of numbers, found a list of 3",
            ),
            (
                "image: a.pgm\nresolution: 1\norigin: 5\n",
                "field `origin` must be a list [x, y, yaw] of numbers, found `5`",
            ),
            (
                "image: a.pgm\nresolution: 1\norigin: [0,0,0]\nnegate: 2\n",
                "field `negate` must be 0 or 1, found `2`",
            ),
            (
                "image: a.pgm\nresolution: 1\norigin: [0,0,0]\noccupied_thresh: 1.5\n",
                "field `occupied_thresh` must be a number in [0, 1], found `1.5`",
            ),
            (
                "image: a.pgm\nresolution: 1\norigin: [0,0,0]\nfree_thresh: 0.9\n",
                "free_thresh 0.9 is greater than occupied_thresh 0.65",
            ),
            (
                "image: a.pgm\nresolution: 1\norigin: [0,0,0]\nmode: fancy\n",
                "field `mode` must be trinary, scale or raw, found `fancy`",
            ),
            (
                "image: [a]\nresolution: 1\norigin: [0,0,0]\n",
                "field `image` must be a file name, found a list of 1",
            ),
            ("- 1\n- 2\n", "expected a mapping of fields"),
            ("image: [\n", "not valid YAML"),
        ];
        for (text, want) in cases {
            let e = meta(text).unwrap_err().to_string();
            assert!(e.starts_with(want), "{text:?}: {e}");
        }
    }

    #[test]
    fn from_memory_matches_the_files() {
        // The in-memory steps (used by fuzz/src/maps.rs) give what the file loaders give.
        let yaml = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/ros/lab.yaml");
        let (map, metric) = load_ros(&yaml, Unknown::Free).unwrap();
        let meta = RosMeta::parse(&std::fs::read_to_string(&yaml).unwrap(), &yaml).unwrap();
        let img = decode_image(&std::fs::read(&meta.image).unwrap(), "lab.pgm").unwrap();
        assert_eq!(ros_map(&meta, &img, Unknown::Free), (map, metric));
    }

    #[test]
    fn classification_follows_ros() {
        let m = meta(OK).unwrap();
        assert_eq!(m.classify(254.0, 255), Occupancy::Free);
        assert_eq!(m.classify(0.0, 255), Occupancy::Occupied);
        assert_eq!(
            m.classify(205.0, 255),
            Occupancy::Unknown,
            "map_saver's unknown"
        );
        // p = (255 - 89) / 255 = 0.651 > 0.65; p(90) = 0.647.
        assert_eq!(m.classify(89.0, 255), Occupancy::Occupied);
        assert_eq!(m.classify(90.0, 255), Occupancy::Unknown);
        // p(206) = 0.192 < 0.196.
        assert_eq!(m.classify(206.0, 255), Occupancy::Free);
        assert_eq!(
            m.classify(254.0, 0),
            Occupancy::Free,
            "trinary ignores alpha"
        );
        let neg = RosMeta {
            negate: true,
            ..m.clone()
        };
        assert_eq!(neg.classify(0.0, 255), Occupancy::Free);
        assert_eq!(neg.classify(255.0, 255), Occupancy::Occupied);
        let scale = RosMeta {
            mode: Mode::Scale,
            ..m.clone()
        };
        assert_eq!(scale.classify(254.0, 128), Occupancy::Unknown);
        assert_eq!(scale.classify(254.0, 255), Occupancy::Free);
        let raw = RosMeta {
            mode: Mode::Raw,
            ..m
        };
        assert_eq!(raw.classify(0.0, 255), Occupancy::Free);
        assert_eq!(raw.classify(100.0, 255), Occupancy::Occupied);
        assert_eq!(raw.classify(50.0, 255), Occupancy::Unknown);
        assert_eq!(raw.classify(255.0, 255), Occupancy::Unknown);
    }
}
