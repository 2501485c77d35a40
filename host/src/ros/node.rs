//! The DDS side of `ohaca ros`: a ROS 2 node (ros2-client over RustDDS) that subscribes to the
//! map, its updates, the goal and the robot's pose, publishes the plan and what it was
//! (`/plan_info`), and serves `compute_path_to_pose`; one loop polls everything and plans in
//! [`Planning`].
//!
//! | topic (default) | type | QoS | what |
//! | --- | --- | --- | --- |
//! | `/map` (sub) | `nav_msgs/OccupancyGrid` | reliable, transient local, depth 1 (as `map_server`) | a new map: sent to the backend |
//! | `/map_updates` (sub) | `map_msgs/OccupancyGridUpdate` | reliable, volatile, depth 10 | cells changed: `SetRect`/`SetCells`, then a warm replan to the current goal |
//! | `/goal_pose` (sub) | `geometry_msgs/PoseStamped` | reliable, volatile, depth 10 | plan from the last start to it |
//! | `/initialpose` (sub; `--start-topic`) | `geometry_msgs/PoseWithCovarianceStamped` | reliable, volatile, depth 10 | the start of later plans |
//! | `/plan` (pub) | `nav_msgs/Path` | reliable, transient local, depth 1 | every plan, in the map's frame |
//! | `/plan_info` (pub) | `std_msgs/String` | reliable, transient local, depth 1 | one JSON object per plan: `seq`, `trigger`, `warm`, times, lengths, backend, the last map upload |
//! | `compute_path_to_pose` (action) | `nav2_msgs/action/ComputePathToPose` | ROS 2 action defaults | [`super::action`] |
//!
//! A message in another frame than the map's is refused (there is no TF here): the map frame
//! is the only one.

use std::net::IpAddr;
use std::path::PathBuf;
use std::time::{Duration, Instant};

use ros2_client::dds::rustdds::DomainParticipantBuilder;
use ros2_client::qos::{Durability, History};
use ros2_client::{
    action::ActionServerQosPolicies, ActionTypeName, Context, MessageTypeName, Name, Node,
    NodeName, NodeOptions, Publisher, QosProfile, ServiceMapping, Subscription,
};

use super::action::PathAction;
use super::convert::{position, ros_path};
use super::msg::{
    error_code, ComputePathGoal, ComputePathResult, OccupancyGrid, OccupancyGridUpdate,
    PoseStamped, PoseWithCovarianceStamped, RosDuration, RosPath, StringMsg, Time,
};
use super::planning::{PlanError, PlanOut, Planning};
use super::record::Recorder;
use crate::map::Map;
use crate::replan::Planned;
use ohaca::Point;

/// Topic and action names (ROS names: `/map`, `map`, `/robot1/map`, ...).
#[derive(Clone, Debug)]
pub struct Topics {
    /// `nav_msgs/OccupancyGrid`.
    pub map: String,
    /// `map_msgs/OccupancyGridUpdate`.
    pub map_updates: String,
    /// `geometry_msgs/PoseStamped`.
    pub goal: String,
    /// `geometry_msgs/PoseWithCovarianceStamped`.
    pub start: String,
    /// `nav_msgs/Path`.
    pub plan: String,
    /// `std_msgs/String`.
    pub plan_info: String,
    /// `nav2_msgs/action/ComputePathToPose`.
    pub action: String,
}

/// QoS of the node's endpoints.
#[derive(Clone, Debug)]
pub struct Qos {
    /// The map subscription.
    pub map: QosProfile,
    /// Updates, goal and start subscriptions.
    pub input: QosProfile,
    /// `/plan` and `/plan_info`.
    pub output: QosProfile,
}

impl Default for Qos {
    fn default() -> Self {
        let reliable = QosProfile::publisher_default();
        Qos {
            map: reliable
                .clone()
                .durability(Durability::TransientLocal)
                .history(History::KeepLast { depth: 1 }),
            input: reliable
                .clone()
                .durability(Durability::Volatile)
                .history(History::KeepLast { depth: 10 }),
            output: reliable
                .durability(Durability::TransientLocal)
                .history(History::KeepLast { depth: 1 }),
        }
    }
}

/// Everything the node needs besides the planner.
pub struct NodeConfig {
    /// The node's name.
    pub name: String,
    /// DDS domain (`ROS_DOMAIN_ID`).
    pub domain: u16,
    /// Use only these local addresses for DDS (e.g. `127.0.0.1`); all when empty.
    pub only_networks: Vec<IpAddr>,
    /// Names.
    pub topics: Topics,
    /// QoS.
    pub qos: Qos,
    /// How the action's services map onto DDS (`Enhanced`: Fast DDS, Connext; `Cyclone`).
    pub service_mapping: ServiceMapping,
    /// `--gif`: draw the plans to the current goal.
    pub gif: Option<PathBuf>,
    /// `--png`: the same as a strip of panels.
    pub png: Option<PathBuf>,
    /// Stop after this long (tests, benchmarks); run until killed otherwise.
    pub run_for: Option<Duration>,
    /// The shortest time between two replans for map updates: updates that arrive sooner are
    /// applied at once and their replan waits until the interval has passed, one replan for the
    /// whole burst (`--min-replan-interval`; zero: a replan after every pass over the topics).
    pub min_replan: Duration,
}

/// Why the node cannot start. The ROS 2 and DDS errors are kept in their `Debug` words (they
/// have no `Display`).
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum NodeError {
    /// A topic or action name is not a ROS name.
    #[error("bad ROS name `{name}`: {why}")]
    Name {
        /// The name given.
        name: String,
        /// ros2-client's reason.
        why: String,
    },
    /// The node's name is not a ROS node name.
    #[error("bad node name `{name}`: {why}")]
    NodeName {
        /// The name given.
        name: String,
        /// ros2-client's reason.
        why: String,
    },
    /// DDS did not start on the domain.
    #[error("cannot start DDS (domain {domain}): {why}")]
    Dds {
        /// The DDS domain.
        domain: u16,
        /// RustDDS's reason.
        why: String,
    },
    /// The ROS 2 context or the node could not be created.
    #[error("cannot start ROS 2: {0}")]
    Ros(String),
    /// A topic, subscription, publisher or the action server could not be created.
    #[error("cannot create {what}: {why}")]
    Create {
        /// The topic or action name.
        what: String,
        /// ros2-client's reason.
        why: String,
    },
}

fn name(s: &str) -> Result<Name, NodeError> {
    let full = if s.starts_with('/') {
        s.to_string()
    } else {
        format!("/{s}")
    };
    Name::parse(&full).map_err(|e| NodeError::Name {
        name: s.to_string(),
        why: format!("{e:?}"),
    })
}

/// The node's endpoints.
struct Endpoints {
    map: Subscription<OccupancyGrid>,
    updates: Subscription<OccupancyGridUpdate>,
    goal: Subscription<PoseStamped>,
    start: Subscription<PoseWithCovarianceStamped>,
    plan: Publisher<RosPath>,
    info: Publisher<StringMsg>,
}

fn endpoints(node: &mut Node, cfg: &NodeConfig) -> Result<(Endpoints, PathAction), NodeError> {
    let t = &cfg.topics;
    let q = &cfg.qos;
    let e = |what: &str, e: ros2_client::CreateError| NodeError::Create {
        what: what.to_string(),
        why: format!("{e:?}"),
    };
    let topic = |n: &str, pkg: &str, ty: &str, qos: &QosProfile| {
        node.create_topic(&name(n)?, MessageTypeName::new(pkg, ty), qos)
            .map_err(|x| e(n, x))
    };
    let map_t = topic(&t.map, "nav_msgs", "OccupancyGrid", &q.map)?;
    let upd_t = topic(&t.map_updates, "map_msgs", "OccupancyGridUpdate", &q.input)?;
    let goal_t = topic(&t.goal, "geometry_msgs", "PoseStamped", &q.input)?;
    let start_t = topic(
        &t.start,
        "geometry_msgs",
        "PoseWithCovarianceStamped",
        &q.input,
    )?;
    let plan_t = topic(&t.plan, "nav_msgs", "Path", &q.output)?;
    let info_t = topic(&t.plan_info, "std_msgs", "String", &q.output)?;
    let service = QosProfile::publisher_default()
        .durability(Durability::Volatile)
        .history(History::KeepLast { depth: 10 });
    let action_qos = ActionServerQosPolicies {
        goal_service: service.clone(),
        result_service: service.clone(),
        cancel_service: service.clone(),
        feedback_publisher: service,
        status_publisher: QosProfile::publisher_default()
            .durability(Durability::TransientLocal)
            .history(History::KeepLast { depth: 1 }),
    };
    let server = node
        .create_action_server(
            cfg.service_mapping,
            &name(&t.action)?,
            &ActionTypeName::new("nav2_msgs", "ComputePathToPose"),
            action_qos,
        )
        .map_err(|x| e(&t.action, x))?;
    let ep = Endpoints {
        map: node
            .create_subscription(&map_t, Some(q.map.clone()))
            .map_err(|x| e(&t.map, x))?,
        updates: node
            .create_subscription(&upd_t, Some(q.input.clone()))
            .map_err(|x| e(&t.map_updates, x))?,
        goal: node
            .create_subscription(&goal_t, Some(q.input.clone()))
            .map_err(|x| e(&t.goal, x))?,
        start: node
            .create_subscription(&start_t, Some(q.input.clone()))
            .map_err(|x| e(&t.start, x))?,
        plan: node
            .create_publisher(&plan_t, Some(q.output.clone()))
            .map_err(|x| e(&t.plan, x))?,
        info: node
            .create_publisher(&info_t, Some(q.output.clone()))
            .map_err(|x| e(&t.plan_info, x))?,
    };
    Ok((ep, PathAction::new(server)))
}

/// Every message waiting on `sub`, oldest first (unreadable ones logged and skipped).
fn take_all<M>(sub: &Subscription<M>, what: &str) -> Vec<M>
where
    M: serde::de::DeserializeOwned + 'static,
{
    let mut out = Vec::new();
    loop {
        match sub.take() {
            Ok(Some((m, _))) => out.push(m),
            Ok(None) => return out,
            Err(e) => log::warn!("{what}: unreadable message skipped: {e:?}"),
        }
    }
}

/// The node's state between messages.
struct State {
    planning: Planning,
    start: Option<[f64; 2]>,
    goal: Option<([f64; 2], f64)>,
    seq: u64,
    recorder: Option<Recorder>,
    /// Plans still to draw (`--gif`).
    to_draw: Vec<(Map, (Point, Point), Planned)>,
    /// Map-update replans, at most one per [`NodeConfig::min_replan`].
    coalesce: Coalesce,
}

/// The replans for map updates, at most one per `min` ([`NodeConfig::min_replan`]).
#[derive(Clone, Copy, Debug)]
struct Coalesce {
    min: Duration,
    /// When the last replan for map updates was made.
    last: Option<Instant>,
    /// Passes with map updates since, whose replan waits.
    pending: u32,
}

impl Coalesce {
    /// One pass over the topics at `now`: `updates` if map updates arrived, `other` if something
    /// else (a goal, a map) makes a plan anyway. Returns whether to plan for the updates now.
    fn pass(&mut self, updates: bool, other: bool, now: Instant) -> bool {
        if updates {
            self.pending = self.pending.saturating_add(1);
        }
        if self.pending == 0 {
            return false;
        }
        let due = other
            || self
                .last
                .is_none_or(|t| now.saturating_duration_since(t) >= self.min);
        if due {
            if self.pending > 1 {
                log::info!("{} map updates coalesced into one replan", self.pending);
            }
            self.pending = 0;
            self.last = Some(now);
        }
        due && !other
    }
}

impl State {
    /// A frame other than the map's, in words.
    fn wrong_frame(&self, frame: &str, what: &str) -> Option<String> {
        let map = self.planning.frame_id()?;
        (!frame.is_empty() && frame != map)
            .then(|| format!("{what} is in frame `{frame}`, not the map's `{map}` (no TF here)"))
    }

    /// Plan from `start` to `goal` and publish it (`/plan`, `/plan_info`).
    fn plan(
        &mut self,
        ep: &Endpoints,
        start: [f64; 2],
        (goal, yaw): ([f64; 2], f64),
        trigger: &str,
    ) -> Result<(RosPath, PlanOut), PlanError> {
        let out = self.planning.plan(start, goal).inspect_err(|e| {
            log::warn!(
                "{trigger}: no plan from ({:.3}, {:.3}) to ({:.3}, {:.3}): {e}",
                start[0],
                start[1],
                goal[0],
                goal[1]
            );
        })?;
        self.seq += 1;
        let path = ros_path(&out.points_m, yaw, &out.frame_id, Time::now());
        let length_m: f64 = out
            .points_m
            .windows(2)
            .map(|w| match w {
                [a, b] => (b[0] - a[0]).hypot(b[1] - a[1]),
                _ => 0.0,
            })
            .sum();
        let info = serde_json::json!({
            "seq": self.seq,
            "trigger": trigger,
            "warm": out.origin.is_warm(),
            "origin": out.origin.name(),
            "planning_time_s": out.elapsed.as_secs_f64(),
            "device_ticks": out.planned.ticks,
            "iterations": out.planned.iterations,
            "poses": path.poses.len(),
            "length_m": length_m,
            "start": start,
            "goal": goal,
            "backend": self.planning.describe(),
            "factor": out.factor,
            "cells": [out.sent_size.0, out.sent_size.1],
            "upload_s": self.planning.last_upload().map(|u| u.0),
            "upload_bytes": self.planning.last_upload().map(|u| u.1),
        });
        log::info!(
            "plan {} ({trigger}): {} poses, {:.2} m, {}, {}, in {:.3} s on {}",
            self.seq,
            path.poses.len(),
            length_m,
            crate::output::count(u64::from(out.planned.iterations), "iteration"),
            out.origin,
            out.elapsed.as_secs_f64(),
            self.planning.describe()
        );
        if let Err(e) = ep.plan.publish(path.clone()) {
            log::warn!("cannot publish the plan: {e:?}");
        }
        if let Err(e) = ep.info.publish(StringMsg {
            data: info.to_string(),
        }) {
            log::warn!("cannot publish the plan info: {e:?}");
        }
        if let (true, Some(map)) = (self.recorder.is_some(), self.planning.sent_map()) {
            self.to_draw
                .push((map.clone(), out.ends, out.planned.clone()));
        }
        Ok((path, out))
    }

    /// `--gif`: draw the plans made since the last call (after the answers went out: drawing
    /// takes a while).
    fn draw(&mut self) {
        let Some(rec) = self.recorder.as_mut() else {
            return;
        };
        for (map, ends, planned) in self.to_draw.drain(..) {
            if let Err(e) = rec.plan(&map, ends, &planned) {
                log::warn!("--gif: {e}");
            }
        }
    }

    /// The action's goal: plan and answer.
    fn action(
        &mut self,
        ep: &Endpoints,
        g: &ComputePathGoal,
    ) -> Result<ComputePathResult, ComputePathResult> {
        let t0 = Instant::now();
        let fail = |code: u16, msg: String| {
            log::warn!("compute_path_to_pose: {msg}");
            ComputePathResult {
                planning_time: RosDuration::from(t0.elapsed()),
                error_code: code,
                error_msg: msg,
                ..ComputePathResult::default()
            }
        };
        let frames = [
            self.wrong_frame(&g.goal.header.frame_id, "the goal"),
            g.use_start
                .then(|| self.wrong_frame(&g.start.header.frame_id, "the start"))
                .flatten(),
        ];
        if let Some(msg) = frames.into_iter().flatten().next() {
            return Err(fail(error_code::TF_ERROR, msg));
        }
        let goal = position(&g.goal.pose).ok_or_else(|| {
            fail(
                error_code::GOAL_OUTSIDE_MAP,
                "the goal is not finite".into(),
            )
        })?;
        let start = if g.use_start {
            position(&g.start.pose).ok_or_else(|| {
                fail(
                    error_code::START_OUTSIDE_MAP,
                    "the start is not finite".into(),
                )
            })?
        } else {
            self.start.ok_or_else(|| {
                fail(
                    error_code::UNKNOWN,
                    "use_start is false and no robot pose arrived yet on the start topic".into(),
                )
            })?
        };
        log::info!(
            "compute_path_to_pose: ({:.3}, {:.3}) -> ({:.3}, {:.3})",
            start[0],
            start[1],
            goal[0],
            goal[1]
        );
        match self.plan(ep, start, (goal, g.goal.pose.orientation.yaw()), "action") {
            Ok((path, _)) => Ok(ComputePathResult {
                path,
                planning_time: RosDuration::from(t0.elapsed()),
                error_code: error_code::NONE,
                error_msg: String::new(),
            }),
            Err(e) => Err(fail(e.code, e.message)),
        }
    }

    /// One pass over the topics; true if anything arrived.
    fn topics(&mut self, ep: &Endpoints) -> bool {
        let mut busy = false;
        let mut replan = None;
        if let Some(g) = take_all(&ep.map, "map").pop() {
            busy = true;
            match self.planning.set_grid(&g) {
                Ok(note) => {
                    log::info!("{}", note.text);
                    if let Some(r) = self.recorder.as_mut() {
                        r.new_map();
                    }
                    replan = Some("map");
                }
                Err(e) => log::error!("map: {e}"),
            }
        }
        for u in take_all(&ep.updates, "map update") {
            busy = true;
            if let Some(msg) = self.wrong_frame(&u.header.frame_id, "a map update") {
                log::warn!("{msg}: ignored");
                continue;
            }
            match self.planning.update(&u) {
                Ok(note) => {
                    log::info!("{}", note.text);
                    if let Some(r) = self.recorder.as_mut() {
                        r.changed(&note.blocked, &note.cleared);
                    }
                    if !(note.blocked.is_empty() && note.cleared.is_empty()) {
                        replan = Some("map_update");
                    }
                }
                Err(e) => log::error!("map update refused: {e}"),
            }
        }
        if let Some(s) = take_all(&ep.start, "start").pop() {
            busy = true;
            match (
                self.wrong_frame(&s.header.frame_id, "the start pose"),
                position(&s.pose.pose),
            ) {
                (Some(msg), _) => log::warn!("{msg}: ignored"),
                (None, None) => log::warn!("a start pose that is not finite: ignored"),
                (None, Some(p)) => {
                    log::info!("start ({:.3}, {:.3})", p[0], p[1]);
                    self.start = Some(p);
                }
            }
        }
        if let Some(g) = take_all(&ep.goal, "goal").pop() {
            busy = true;
            match (
                self.wrong_frame(&g.header.frame_id, "the goal"),
                position(&g.pose),
            ) {
                (Some(msg), _) => log::warn!("{msg}: ignored"),
                (None, None) => log::warn!("a goal that is not finite: ignored"),
                (None, Some(p)) => {
                    log::info!("goal ({:.3}, {:.3})", p[0], p[1]);
                    self.goal = Some((p, g.pose.orientation.yaw()));
                    replan = Some("goal");
                }
            }
        }
        // Coalescing: a replan for map updates waits until `min_replan` has passed since the
        // last one; a new goal or map plans at once (and takes the waiting updates with it).
        let updates = replan == Some("map_update");
        let other = replan.is_some() && !updates;
        if self.coalesce.pass(updates, other, Instant::now()) {
            replan = Some("map_update");
        } else if updates {
            replan = None;
        }
        if let Some(trigger) = replan {
            match (self.start, self.goal) {
                (Some(s), Some(g)) => {
                    let _ = self.plan(ep, s, g, trigger);
                }
                (None, Some(_)) => {
                    log::warn!("a goal but no start yet: waiting for the start topic")
                }
                _ => {}
            }
        }
        busy
    }
}

/// Run the node until killed (or for `cfg.run_for`).
pub fn run(cfg: NodeConfig, planning: Planning) -> Result<(), NodeError> {
    let mut builder = DomainParticipantBuilder::new(cfg.domain);
    if !cfg.only_networks.is_empty() {
        builder = builder.with_only_networks(cfg.only_networks.iter().copied());
    }
    let participant = builder.build().map_err(|e| NodeError::Dds {
        domain: cfg.domain,
        why: format!("{e:?}"),
    })?;
    let context = Context::from_domain_participant(participant)
        .map_err(|e| NodeError::Ros(format!("{e:?}")))?;
    let node_name = NodeName::new("/", &cfg.name).map_err(|e| NodeError::NodeName {
        name: cfg.name.clone(),
        why: format!("{e:?}"),
    })?;
    let mut node = context
        .new_node(node_name, NodeOptions::new().enable_rosout(false))
        .map_err(|e| NodeError::Create {
            what: "the node".into(),
            why: format!("{e:?}"),
        })?;
    let (ep, mut action) = endpoints(&mut node, &cfg)?;
    let t = &cfg.topics;
    log::info!(
        "node /{} on DDS domain {}: map `{}`, updates `{}`, goal `{}`, start `{}` -> plan `{}`, \
         info `{}`, action `{}` ({:?} service mapping); planning on {}",
        cfg.name,
        cfg.domain,
        t.map,
        t.map_updates,
        t.goal,
        t.start,
        t.plan,
        t.plan_info,
        t.action,
        cfg.service_mapping,
        planning.describe()
    );
    let mut state = State {
        planning,
        start: None,
        goal: None,
        seq: 0,
        recorder: (cfg.gif.is_some() || cfg.png.is_some())
            .then(|| Recorder::new(cfg.gif.clone(), cfg.png.clone())),
        to_draw: Vec::new(),
        coalesce: Coalesce {
            min: cfg.min_replan,
            last: None,
            pending: 0,
        },
    };
    let began = Instant::now();
    loop {
        let mut busy = state.topics(&ep);
        busy |= action.poll(&mut |g| state.action(&ep, g));
        state.draw();
        if cfg.run_for.is_some_and(|d| began.elapsed() >= d) {
            log::info!("stopping after {:.1} s", began.elapsed().as_secs_f64());
            return Ok(());
        }
        if !busy {
            std::thread::sleep(Duration::from_millis(5));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn map_update_replans_are_coalesced() {
        let t0 = Instant::now();
        let ms = |n: u64| t0 + Duration::from_millis(n);
        let mut c = Coalesce {
            min: Duration::from_millis(500),
            last: None,
            pending: 0,
        };
        assert!(c.pass(true, false, ms(0)), "the first update plans at once");
        assert!(!c.pass(true, false, ms(100)), "the next waits");
        assert!(!c.pass(true, false, ms(300)), "and the one after");
        assert!(!c.pass(false, false, ms(400)), "still within the interval");
        assert!(c.pass(false, false, ms(500)), "one replan for the burst");
        assert!(!c.pass(false, false, ms(600)), "nothing pending");
        assert!(!c.pass(true, false, ms(700)), "waits again");
        assert!(
            !c.pass(false, true, ms(800)),
            "a goal plans and takes the updates along"
        );
        assert!(!c.pass(false, false, ms(2000)), "nothing left");
        let mut every = Coalesce {
            min: Duration::ZERO,
            last: None,
            pending: 0,
        };
        assert!(every.pass(true, false, ms(0)) && every.pass(true, false, ms(0)));
    }
}
