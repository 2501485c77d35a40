//! `ohaca ros`: the planner as a ROS 2 node, in pure Rust (ros2-client over RustDDS: no ROS
//! installation). It takes the map, its updates, the goal and the robot's pose from ROS topics,
//! plans on the host core or a device (the same link as `ohaca send`), and answers with
//! `nav_msgs/Path` on `/plan` and through Nav2's `compute_path_to_pose` action. `docs/ROS.md`
//! has the topics, QoS, Nav2 set-up and limits.
//!
//! | module | owns |
//! | --- | --- |
//! | [`msg`] | the ROS 2 message types (CDR layout of the ROS IDL) |
//! | [`convert`] | occupancy grid <-> map and frame, updates, poses, the path message |
//! | [`backend`] | what plans: the host core or a device over its link |
//! | [`planning`] | the map as received, inflated and fitted; updates as cell changes; plans in metres |
//! | [`action`] | the `compute_path_to_pose` action server |
//! | [`record`] | `--gif`: the plans to one goal drawn as a drive |
//! | [`logger`] | the log lines on stderr |
//! | [`node`] | the DDS node: topics, QoS, the loop |

pub mod action;
pub mod backend;
pub mod convert;
pub mod logger;
pub mod msg;
pub mod node;
pub mod planning;
pub mod record;
