//! `ohaca ros`: run the planner as a ROS 2 node ([`ohaca_host::ros`]): subscribe to the map, its
//! updates, the goal and the robot's pose, publish `/plan` and `/plan_info`, serve Nav2's
//! `compute_path_to_pose`. Plans on a device (`--tcp`, `--serial`: the link of `ohaca send`) or
//! on the host core (`--host`). Runs until killed (or `--run-for`); logs one line per event on
//! stderr. `docs/ROS.md` has the details.
//!
//! Exit codes: 0 after `--run-for`; 2 bad flags or DDS could not start.

use std::net::IpAddr;
use std::path::PathBuf;
use std::time::Duration;

use ohaca_host::board::BoardArg;
use ohaca_host::link::{Link, DEFAULT_BAUD};
use ohaca_host::map::Unknown;
use ohaca_host::ros::backend::{Backend, Connect, DeviceBackend, HostBackend};
use ohaca_host::ros::convert::Occupancy01;
use ohaca_host::ros::logger;
use ohaca_host::ros::node::{run as run_node, NodeConfig, Qos, Topics};
use ohaca_host::ros::planning::Planning;
use ohaca_host::{exit, ParamArgs};
use ros2_client::qos::{Durability, Reliability, WhenFull};
use ros2_client::ServiceMapping;

use super::bad_input;

/// DDS durability, as a flag value.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum DurabilityArg {
    /// Late subscribers get the last sample.
    TransientLocal,
    /// Only samples published while subscribed.
    Volatile,
}

/// DDS reliability, as a flag value.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum ReliabilityArg {
    /// Retransmitted until acknowledged.
    Reliable,
    /// Sent once.
    BestEffort,
}

/// The action's service mapping, as a flag value.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum MappingArg {
    /// The RPC-over-DDS "enhanced" mapping (rmw_fastrtps, rmw_connextdds): ROS 2's default.
    Enhanced,
    /// rmw_cyclonedds's mapping (a request header in the payload).
    Cyclone,
    /// The RPC-over-DDS "basic" mapping.
    Basic,
}

/// Arguments of `ohaca ros`.
#[derive(clap::Args, Debug)]
#[command(group(clap::ArgGroup::new("planner").required(true).args(["host", "tcp", "serial"])))]
pub struct Args {
    /// Plan on the host core
    #[arg(long)]
    pub host: bool,
    /// With --host: plan exactly as this board's firmware does (its buffers, layout and path
    /// bound; maps larger than it takes are fitted as for a device): f411 (also the default QEMU
    /// firmware) or h743 (also its QEMU twin) [default: as the f411, with heap storage on maps
    /// larger than its arena, and no fitting]
    #[arg(long, value_enum, value_name = "BOARD", conflicts_with_all = ["tcp", "serial"])]
    pub board: Option<BoardArg>,
    /// Plan on a device on a TCP port, e.g. QEMU's UART (scripts/qemu-serve.sh): HOST:PORT
    #[arg(long, value_name = "HOST:PORT")]
    pub tcp: Option<String>,
    /// Plan on a device on a serial port, e.g. /dev/ttyUSB0
    #[arg(long, value_name = "DEVICE")]
    pub serial: Option<String>,
    /// Serial line speed
    #[arg(long, value_name = "N", default_value_t = DEFAULT_BAUD)]
    pub baud: u32,
    /// Seconds to wait for each reply of the device
    #[arg(long, value_name = "SECONDS", default_value_t = 30.0)]
    pub timeout: f64,

    /// Unknown cells (-1, or between the thresholds) are blocked or free
    #[arg(long, value_name = "AS", value_enum, default_value_t = Unknown::Blocked)]
    pub unknown: Unknown,
    /// Block every cell whose centre is within this radius (metres) of an obstacle's centre
    #[arg(long, value_name = "METRES")]
    pub inflate: Option<f64>,
    /// Occupancy (0-1) above which a cell is blocked (map_server's occupied_thresh)
    #[arg(long, value_name = "P", default_value_t = 0.65)]
    pub occupied_thresh: f64,
    /// Occupancy (0-1) below which a cell is free (map_server's free_thresh)
    #[arg(long, value_name = "P", default_value_t = 0.196)]
    pub free_thresh: f64,

    /// DDS domain [default: $ROS_DOMAIN_ID, else 0]
    #[arg(long, value_name = "N")]
    pub domain: Option<u16>,
    /// Use only this local address for DDS (repeatable), e.g. 127.0.0.1 for loopback only
    #[arg(long, value_name = "IP")]
    pub only_network: Vec<IpAddr>,
    /// The node's name
    #[arg(long, value_name = "NAME", default_value = "ohaca_planner")]
    pub node_name: String,
    /// Map topic (nav_msgs/OccupancyGrid)
    #[arg(long, value_name = "NAME", default_value = "/map")]
    pub map_topic: String,
    /// Map updates topic (map_msgs/OccupancyGridUpdate)
    #[arg(long, value_name = "NAME", default_value = "/map_updates")]
    pub map_updates_topic: String,
    /// Goal topic (geometry_msgs/PoseStamped)
    #[arg(long, value_name = "NAME", default_value = "/goal_pose")]
    pub goal_topic: String,
    /// Start topic (geometry_msgs/PoseWithCovarianceStamped), e.g. /amcl_pose
    #[arg(long, value_name = "NAME", default_value = "/initialpose")]
    pub start_topic: String,
    /// Plan topic (nav_msgs/Path)
    #[arg(long, value_name = "NAME", default_value = "/plan")]
    pub plan_topic: String,
    /// Plan info topic (std_msgs/String, one JSON object per plan)
    #[arg(long, value_name = "NAME", default_value = "/plan_info")]
    pub plan_info_topic: String,
    /// Action name (nav2_msgs/action/ComputePathToPose)
    #[arg(long, value_name = "NAME", default_value = "/compute_path_to_pose")]
    pub action_name: String,
    /// Map subscription durability (map_server publishes transient-local)
    #[arg(long, value_name = "D", value_enum, default_value_t = DurabilityArg::TransientLocal)]
    pub map_durability: DurabilityArg,
    /// Map subscription reliability
    #[arg(long, value_name = "R", value_enum, default_value_t = ReliabilityArg::Reliable)]
    pub map_reliability: ReliabilityArg,
    /// Reliability of the update, goal and start subscriptions
    #[arg(long, value_name = "R", value_enum, default_value_t = ReliabilityArg::Reliable)]
    pub input_reliability: ReliabilityArg,
    /// Durability of /plan and /plan_info
    #[arg(long, value_name = "D", value_enum, default_value_t = DurabilityArg::TransientLocal)]
    pub output_durability: DurabilityArg,
    /// How the action's services map onto DDS: enhanced (Fast DDS, Connext) or cyclone
    #[arg(long, value_name = "M", value_enum, default_value_t = MappingArg::Enhanced)]
    pub service_mapping: MappingArg,

    /// Draw the plans to the current goal (and the updates between them) as an animated GIF
    #[arg(long, value_name = "FILE")]
    pub gif: Option<PathBuf>,
    /// Draw the same as a strip of PNG panels, one per plan
    #[arg(long, value_name = "FILE")]
    pub png: Option<PathBuf>,
    /// Stop after this many seconds (default: run until killed)
    #[arg(long, value_name = "SECONDS")]
    pub run_for: Option<f64>,
    /// The shortest time between two replans for map updates: a burst of `/map_updates` within
    /// it is applied at once and replanned once when it has passed (0: replan after every pass)
    #[arg(long, value_name = "SECONDS", default_value_t = 0.0)]
    pub min_replan_interval: f64,
    /// Log level: error, warn, info or debug (debug also shows the DDS libraries' lines)
    #[arg(long, value_name = "LEVEL", default_value = "info")]
    pub log_level: log::Level,
    #[command(flatten)]
    pub params: ParamArgs,
}

/// Why `ohaca ros` cannot start (printed as `error: ...`, exit code 2).
#[derive(Debug, thiserror::Error)]
enum RosError {
    /// A duration flag is not a positive number of seconds (up to a year).
    #[error("{flag} must be a positive number of seconds, not {value}")]
    Seconds {
        /// The flag.
        flag: &'static str,
        /// Its value.
        value: f64,
    },
    /// The parameters are out of range (the core's words).
    #[error("{0}")]
    Params(ohaca::Error),
    /// `ROS_DOMAIN_ID` is not a number.
    #[error("ROS_DOMAIN_ID `{0}` is not a domain number")]
    DomainVar(String),
    /// The domain is out of DDS's range.
    #[error("DDS domain {0} is not in 0..=232")]
    Domain(u16),
}

fn seconds(value: f64, flag: &'static str) -> Result<Duration, RosError> {
    let bad = RosError::Seconds { flag, value };
    if !(value > 0.0 && value <= 86_400.0 * 365.0) {
        return Err(bad);
    }
    Duration::try_from_secs_f64(value).map_err(|_| bad)
}

fn backend(args: &Args) -> Result<Box<dyn Backend>, RosError> {
    let params = args.params.params();
    params.validate().map_err(RosError::Params)?;
    let timeout = seconds(args.timeout, "--timeout")?;
    if let Some(addr) = &args.tcp {
        let a = addr.clone();
        let connect: Connect<_> = Box::new(move || Link::tcp(&a, timeout));
        return Ok(Box::new(DeviceBackend::new(addr, connect, params)));
    }
    if let Some(port) = &args.serial {
        let (p, baud) = (port.clone(), args.baud);
        let connect: Connect<_> = Box::new(move || Link::serial(&p, baud, timeout));
        return Ok(Box::new(DeviceBackend::new(port, connect, params)));
    }
    Ok(Box::new(match args.board {
        None => HostBackend::new(params),
        Some(b) => HostBackend::on(params, b.board()),
    }))
}

fn config(args: &Args) -> Result<NodeConfig, RosError> {
    let domain = match args.domain {
        Some(d) => d,
        None => match std::env::var("ROS_DOMAIN_ID") {
            Ok(v) if !v.trim().is_empty() => v
                .trim()
                .parse()
                .map_err(|_| RosError::DomainVar(v.clone()))?,
            _ => 0,
        },
    };
    if domain > 232 {
        return Err(RosError::Domain(domain));
    }
    let durability = |d: DurabilityArg| match d {
        DurabilityArg::TransientLocal => Durability::TransientLocal,
        DurabilityArg::Volatile => Durability::Volatile,
    };
    let reliability = |r: ReliabilityArg| match r {
        ReliabilityArg::Reliable => Reliability::Reliable {
            when_full: WhenFull::DEFAULT,
        },
        ReliabilityArg::BestEffort => Reliability::BestEffort,
    };
    let q = Qos::default();
    let qos = Qos {
        map: q
            .map
            .durability(durability(args.map_durability))
            .reliability(reliability(args.map_reliability)),
        input: q.input.reliability(reliability(args.input_reliability)),
        output: q.output.durability(durability(args.output_durability)),
    };
    Ok(NodeConfig {
        name: args.node_name.clone(),
        domain,
        only_networks: args.only_network.clone(),
        topics: Topics {
            map: args.map_topic.clone(),
            map_updates: args.map_updates_topic.clone(),
            goal: args.goal_topic.clone(),
            start: args.start_topic.clone(),
            plan: args.plan_topic.clone(),
            plan_info: args.plan_info_topic.clone(),
            action: args.action_name.clone(),
        },
        qos,
        service_mapping: match args.service_mapping {
            MappingArg::Enhanced => ServiceMapping::Enhanced,
            MappingArg::Cyclone => ServiceMapping::Cyclone,
            MappingArg::Basic => ServiceMapping::Basic,
        },
        gif: args.gif.clone(),
        png: args.png.clone(),
        run_for: args.run_for.map(|v| seconds(v, "--run-for")).transpose()?,
        min_replan: if args.min_replan_interval == 0.0 {
            Duration::ZERO
        } else {
            seconds(args.min_replan_interval, "--min-replan-interval")?
        },
    })
}

/// Run `ohaca ros`; returns the exit code.
pub fn run(args: &Args) -> u8 {
    let ok = |p: f64| (0.0..=1.0).contains(&p);
    if !(ok(args.occupied_thresh)
        && ok(args.free_thresh)
        && args.free_thresh <= args.occupied_thresh)
    {
        return bad_input(format!(
            "thresholds must be in [0, 1] with --free-thresh ({}) <= --occupied-thresh ({})",
            args.free_thresh, args.occupied_thresh
        ));
    }
    if args.inflate.is_some_and(|r| !(r.is_finite() && r >= 0.0)) {
        return bad_input("--inflate must be a length >= 0 in metres");
    }
    let rule = Occupancy01 {
        occupied_thresh: args.occupied_thresh,
        free_thresh: args.free_thresh,
        unknown: args.unknown,
    };
    let (cfg, backend) = match config(args).and_then(|c| Ok((c, backend(args)?))) {
        Ok(x) => x,
        Err(e) => return bad_input(e),
    };
    logger::init(args.log_level);
    let planning = Planning::new(backend, rule, args.inflate);
    match run_node(cfg, planning) {
        Ok(()) => exit::FOUND,
        Err(e) => bad_input(e),
    }
}
