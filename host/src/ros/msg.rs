//! The ROS 2 messages `ohaca ros` reads and writes, as serde types whose CDR layout is the ROS 2
//! IDL's field by field (ros2-client serializes them with CDR; ROS 2 names and types are in
//! [`super::names`]). Only the fields ROS defines, in ROS's order: nothing here is ours.
//!
//! | type | ROS 2 message |
//! | --- | --- |
//! | [`Time`], [`RosDuration`] | `builtin_interfaces/Time`, `builtin_interfaces/Duration` |
//! | [`Header`] | `std_msgs/Header` |
//! | [`Pose`], [`PoseStamped`], [`PoseWithCovarianceStamped`] | `geometry_msgs/...` |
//! | [`OccupancyGrid`], [`MapMetaData`] | `nav_msgs/OccupancyGrid`, `nav_msgs/MapMetaData` |
//! | [`RosPath`] | `nav_msgs/Path` |
//! | [`OccupancyGridUpdate`] | `map_msgs/OccupancyGridUpdate` |
//! | [`StringMsg`] | `std_msgs/String` (the `/plan_info` topic, JSON text) |
//! | [`ComputePathGoal`], [`ComputePathResult`], [`ComputePathFeedback`] | `nav2_msgs/action/ComputePathToPose` (Jazzy) |

use ros2_client::Message;
use serde::de::{Error as _, SeqAccess, Visitor};
use serde::{Deserialize, Deserializer, Serialize, Serializer};

/// `builtin_interfaces/Time`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Time {
    /// Seconds.
    pub sec: i32,
    /// Nanoseconds, `0..1e9`.
    pub nanosec: u32,
}

impl Time {
    /// The wall clock now (0 if the clock is before 1970).
    pub fn now() -> Time {
        let d = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .unwrap_or_default();
        Time {
            sec: i32::try_from(d.as_secs()).unwrap_or(i32::MAX),
            nanosec: d.subsec_nanos(),
        }
    }
}

/// `builtin_interfaces/Duration`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct RosDuration {
    /// Seconds.
    pub sec: i32,
    /// Nanoseconds, `0..1e9`.
    pub nanosec: u32,
}

impl From<std::time::Duration> for RosDuration {
    fn from(d: std::time::Duration) -> Self {
        RosDuration {
            sec: i32::try_from(d.as_secs()).unwrap_or(i32::MAX),
            nanosec: d.subsec_nanos(),
        }
    }
}

/// `std_msgs/Header`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Header {
    /// When.
    pub stamp: Time,
    /// The frame the data is in (e.g. `map`).
    pub frame_id: String,
}

/// `geometry_msgs/Point`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Point3 {
    /// x (m).
    pub x: f64,
    /// y (m).
    pub y: f64,
    /// z (m).
    pub z: f64,
}

/// `geometry_msgs/Quaternion`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Quaternion {
    /// x.
    pub x: f64,
    /// y.
    pub y: f64,
    /// z.
    pub z: f64,
    /// w.
    pub w: f64,
}

impl Default for Quaternion {
    fn default() -> Self {
        Quaternion::from_yaw(0.0)
    }
}

impl Quaternion {
    /// A rotation by `yaw` radians about z.
    pub fn from_yaw(yaw: f64) -> Quaternion {
        let (s, c) = (yaw / 2.0).sin_cos();
        Quaternion {
            x: 0.0,
            y: 0.0,
            z: s,
            w: c,
        }
    }

    /// The rotation about z (radians, `-pi..=pi`); 0 for a zero or non-finite quaternion.
    pub fn yaw(&self) -> f64 {
        let siny = 2.0 * (self.w * self.z + self.x * self.y);
        let cosy = 1.0 - 2.0 * (self.y * self.y + self.z * self.z);
        let yaw = siny.atan2(cosy);
        if yaw.is_finite() {
            yaw
        } else {
            0.0
        }
    }
}

/// `geometry_msgs/Pose`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Pose {
    /// Position (m).
    pub position: Point3,
    /// Orientation.
    pub orientation: Quaternion,
}

/// `geometry_msgs/PoseStamped` (`/goal_pose`, the poses of a path, the action's goal and start).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct PoseStamped {
    /// Stamp and frame.
    pub header: Header,
    /// The pose.
    pub pose: Pose,
}
impl Message for PoseStamped {}

/// `float64[36]`, a 6 x 6 covariance: a fixed-size CDR array (no length), which serde's arrays
/// (at most 32 elements) do not cover.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Covariance(pub [f64; 36]);

impl Default for Covariance {
    fn default() -> Self {
        Covariance([0.0; 36])
    }
}

impl Serialize for Covariance {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeTuple;
        let mut t = s.serialize_tuple(36)?;
        for v in &self.0 {
            t.serialize_element(v)?;
        }
        t.end()
    }
}

impl<'de> Deserialize<'de> for Covariance {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = Covariance;
            fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str("36 float64 values")
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Covariance, A::Error> {
                let mut out = [0.0; 36];
                for (i, slot) in out.iter_mut().enumerate() {
                    *slot = seq
                        .next_element()?
                        .ok_or_else(|| A::Error::invalid_length(i, &self))?;
                }
                Ok(Covariance(out))
            }
        }
        d.deserialize_tuple(36, V)
    }
}

/// `geometry_msgs/PoseWithCovariance`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct PoseWithCovariance {
    /// The pose.
    pub pose: Pose,
    /// Its covariance (row-major 6 x 6).
    pub covariance: Covariance,
}

/// `geometry_msgs/PoseWithCovarianceStamped` (`/initialpose`, `/amcl_pose`).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct PoseWithCovarianceStamped {
    /// Stamp and frame.
    pub header: Header,
    /// The pose.
    pub pose: PoseWithCovariance,
}
impl Message for PoseWithCovarianceStamped {}

/// `nav_msgs/MapMetaData`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct MapMetaData {
    /// When the map was loaded.
    pub map_load_time: Time,
    /// Metres per cell.
    pub resolution: f32,
    /// Cells per row.
    pub width: u32,
    /// Rows.
    pub height: u32,
    /// The pose of cell (0, 0)'s lower-left corner in the map frame.
    pub origin: Pose,
}

/// `nav_msgs/OccupancyGrid` (`/map`): row-major from the origin cell, rows going +y; each cell
/// -1 (unknown) or an occupancy 0..=100.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct OccupancyGrid {
    /// Stamp and frame.
    pub header: Header,
    /// Size, resolution, origin.
    pub info: MapMetaData,
    /// The cells.
    pub data: Vec<i8>,
}
impl Message for OccupancyGrid {}

/// `map_msgs/OccupancyGridUpdate` (`/map_updates`): a window of the map, in the map's cells.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct OccupancyGridUpdate {
    /// Stamp and frame.
    pub header: Header,
    /// Column of the window's first cell.
    pub x: i32,
    /// Row (from the origin, +y) of the window's first cell.
    pub y: i32,
    /// Window width.
    pub width: u32,
    /// Window height.
    pub height: u32,
    /// The window's cells, row-major as in [`OccupancyGrid`].
    pub data: Vec<i8>,
}
impl Message for OccupancyGridUpdate {}

/// `nav_msgs/Path` (`/plan`).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct RosPath {
    /// Stamp and frame (the map's).
    pub header: Header,
    /// The poses, start first.
    pub poses: Vec<PoseStamped>,
}
impl Message for RosPath {}

/// `std_msgs/String`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct StringMsg {
    /// The text.
    pub data: String,
}
impl Message for StringMsg {}

/// The goal of `nav2_msgs/action/ComputePathToPose`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ComputePathGoal {
    /// Where to go.
    pub goal: PoseStamped,
    /// Where from, if `use_start`.
    pub start: PoseStamped,
    /// The planner plugin asked for (ignored: there is one).
    pub planner_id: String,
    /// Plan from `start`; otherwise from the robot's pose (the start topic).
    pub use_start: bool,
}
impl Message for ComputePathGoal {}

/// The result of `nav2_msgs/action/ComputePathToPose` (Jazzy: with `error_msg`).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ComputePathResult {
    /// The path (empty on failure).
    pub path: RosPath,
    /// Time from the request to the path.
    pub planning_time: RosDuration,
    /// [`error_code`] values.
    pub error_code: u16,
    /// What went wrong, in words (empty on success).
    pub error_msg: String,
}
impl Message for ComputePathResult {}

/// The (empty) feedback of `ComputePathToPose`: ROS 2 IDL gives an empty message one `uint8`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ComputePathFeedback {
    /// Always 0.
    pub structure_needs_at_least_one_member: u8,
}
impl Message for ComputePathFeedback {}

/// `ComputePathToPose` result error codes (Nav2 Jazzy).
pub mod error_code {
    /// Success.
    pub const NONE: u16 = 0;
    /// Anything else (device errors).
    pub const UNKNOWN: u16 = 200;
    /// A frame that is not the map's.
    pub const TF_ERROR: u16 = 202;
    /// Start off the map.
    pub const START_OUTSIDE_MAP: u16 = 203;
    /// Goal off the map.
    pub const GOAL_OUTSIDE_MAP: u16 = 204;
    /// Start on an obstacle.
    pub const START_OCCUPIED: u16 = 205;
    /// Goal on an obstacle.
    pub const GOAL_OCCUPIED: u16 = 206;
    /// The device did not answer in time.
    pub const TIMEOUT: u16 = 207;
    /// No path.
    pub const NO_VALID_PATH: u16 = 208;
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn yaw_round_trips() {
        for yaw in [0.0, 0.5, -1.2, 3.0] {
            assert!((Quaternion::from_yaw(yaw).yaw() - yaw).abs() < 1e-12);
        }
        let q = Quaternion {
            x: 0.0,
            y: 0.0,
            z: 0.0,
            w: 0.0,
        };
        assert_eq!(q.yaw(), 0.0);
    }

    #[test]
    fn covariance_is_36_values_without_a_length() {
        let mut c = Covariance::default();
        c.0[35] = 2.5;
        let v = serde_json::to_value(c).unwrap();
        assert_eq!(v.as_array().unwrap().len(), 36);
        let back: Covariance = serde_json::from_value(v).unwrap();
        assert_eq!(back, c);
        assert!(serde_json::from_str::<Covariance>("[1.0, 2.0]").is_err());
    }
}
