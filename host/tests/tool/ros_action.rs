//! `ohaca ros`'s `compute_path_to_pose` action with ROS 2's default service mapping ("enhanced",
//! rmw_fastrtps's), called by ros2-client's own action client over RustDDS on loopback: a goal
//! that succeeds, one off the map (Nav2's `GOAL_OUTSIDE_MAP`), and a device that cannot be reached
//! (an error to the caller, not a hang). The Cyclone DDS side, with rmw_cyclonedds's mapping, is
//! `scripts/ros_interop.py`.

use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use ohaca_host::ros::msg::{
    error_code, ComputePathFeedback, ComputePathGoal, ComputePathResult, Header, MapMetaData,
    OccupancyGrid, Point3, Pose, PoseStamped, Quaternion, Time,
};
use ros2_client::action::{ActionClient, ActionClientQosPolicies, GoalStatusEnum};
use ros2_client::dds::rustdds::DomainParticipantBuilder;
use ros2_client::qos::{Durability, History};
use ros2_client::{
    ActionTypeName, Context, MessageTypeName, Name, Node, NodeName, NodeOptions, Publisher,
    QosProfile, ServiceMapping,
};

/// The node under test; killed on drop.
struct OhacaRos(Child);

impl Drop for OhacaRos {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

fn ohaca_ros(domain: u16, planner: &[&str]) -> OhacaRos {
    let child = Command::new(env!("CARGO_BIN_EXE_ohaca"))
        .args([
            "ros",
            "--domain",
            &domain.to_string(),
            "--only-network",
            "127.0.0.1",
        ])
        .args(["--run-for", "120", "--timeout", "2"])
        .args(planner)
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .expect("start ohaca ros");
    OhacaRos(child)
}

/// A domain of its own for each test process and node.
fn domain(k: u16) -> u16 {
    100 + (std::process::id() % 60) as u16 + 60 * k
}

fn client_node(domain: u16) -> Node {
    let dp = DomainParticipantBuilder::new(domain)
        .with_only_networks([std::net::Ipv4Addr::LOCALHOST])
        .build()
        .expect("DDS");
    let ctx = Context::from_domain_participant(dp).expect("context");
    ctx.new_node(
        NodeName::new("/", "ohaca_test_client").expect("name"),
        NodeOptions::new().enable_rosout(false),
    )
    .expect("node")
}

/// A 40 x 30 map of 0.1 m from (-1, -1), free but a wall at column 20, rows 0..25.
fn map_message() -> OccupancyGrid {
    OccupancyGrid {
        header: Header {
            stamp: Time::now(),
            frame_id: "map".into(),
        },
        info: MapMetaData {
            map_load_time: Time::default(),
            resolution: 0.1,
            width: 40,
            height: 30,
            origin: Pose {
                position: Point3 {
                    x: -1.0,
                    y: -1.0,
                    z: 0.0,
                },
                orientation: Quaternion::default(),
            },
        },
        data: (0..40 * 30)
            .map(|i| if i % 40 == 20 && i / 40 < 25 { 100 } else { 0 })
            .collect(),
    }
}

fn map_publisher(node: &mut Node) -> Publisher<OccupancyGrid> {
    let qos = QosProfile::publisher_default()
        .durability(Durability::TransientLocal)
        .history(History::KeepLast { depth: 1 });
    let topic = node
        .create_topic(
            &Name::new("/", "map").expect("name"),
            MessageTypeName::new("nav_msgs", "OccupancyGrid"),
            &qos,
        )
        .expect("topic");
    node.create_publisher(&topic, Some(qos)).expect("publisher")
}

type Client = ActionClient<ComputePathGoal, ComputePathResult, ComputePathFeedback>;

fn action_client(node: &mut Node) -> Client {
    let service = QosProfile::publisher_default()
        .durability(Durability::Volatile)
        .history(History::KeepLast { depth: 10 });
    let qos = ActionClientQosPolicies {
        goal_service: service.clone(),
        result_service: service.clone(),
        cancel_service: service.clone(),
        feedback_subscription: service,
        status_subscription: QosProfile::publisher_default()
            .durability(Durability::TransientLocal)
            .history(History::KeepLast { depth: 1 }),
    };
    node.create_action_client(
        ServiceMapping::Enhanced,
        &Name::new("/", "compute_path_to_pose").expect("name"),
        &ActionTypeName::new("nav2_msgs", "ComputePathToPose"),
        qos,
    )
    .expect("action client")
}

fn pose(x: f64, y: f64) -> PoseStamped {
    PoseStamped {
        header: Header {
            stamp: Time::now(),
            frame_id: "map".into(),
        },
        pose: Pose {
            position: Point3 { x, y, z: 0.0 },
            orientation: Quaternion::default(),
        },
    }
}

const WAIT: Duration = Duration::from_secs(30);

/// Call the action (the goal is sent again each second until the server answers: a request sent
/// before discovery is lost) and wait for its result.
fn call(client: &Client, start: [f64; 2], goal: [f64; 2]) -> (GoalStatusEnum, ComputePathResult) {
    let g = ComputePathGoal {
        goal: pose(goal[0], goal[1]),
        start: pose(start[0], start[1]),
        planner_id: String::new(),
        use_start: true,
    };
    let t0 = Instant::now();
    let goal_id = 'sent: loop {
        assert!(
            t0.elapsed() < WAIT,
            "no answer to the goal within {WAIT:?}: is the node discovered on loopback?"
        );
        let (req, goal_id) = client.send_goal(g.clone()).expect("send goal");
        let resent = Instant::now();
        while resent.elapsed() < Duration::from_secs(1) {
            if let Some(r) = client.receive_goal_response(req).expect("goal response") {
                assert!(r.accepted, "the goal was refused");
                break 'sent goal_id;
            }
            std::thread::sleep(Duration::from_millis(10));
        }
    };
    let req = client.request_result(goal_id).expect("request result");
    let t1 = Instant::now();
    while t1.elapsed() < WAIT {
        if let Some(r) = client.receive_result(req).expect("result") {
            return r;
        }
        std::thread::sleep(Duration::from_millis(10));
    }
    panic!("no result within {WAIT:?}");
}

#[test]
fn the_action_plans_and_answers_errors_with_nav2_codes() {
    let d = domain(0);
    let _node = ohaca_ros(d, &["--host"]);
    let mut me = client_node(d);
    let map = map_publisher(&mut me);
    map.publish(map_message()).expect("publish the map");
    let client = action_client(&mut me);
    // Around the wall: (-0.95, -0.95) is the bottom-left cell; (1.25, -0.95) across the wall.
    let (start, goal) = ([-0.95, -0.95], [1.25, -0.95]);
    let (status, r) = call(&client, start, goal);
    assert_eq!(status, GoalStatusEnum::Succeeded, "{r:?}");
    assert_eq!(r.error_code, error_code::NONE, "{}", r.error_msg);
    assert_eq!(r.path.header.frame_id, "map");
    let pts: Vec<[f64; 2]> = r
        .path
        .poses
        .iter()
        .map(|p| [p.pose.position.x, p.pose.position.y])
        .collect();
    assert_eq!(pts.first(), Some(&start));
    assert_eq!(pts.last(), Some(&goal));
    assert!(
        pts.iter().any(|p| p[1] > 1.4),
        "the path goes over the wall's end: {pts:?}"
    );
    let (status, r) = call(&client, start, [9.0, 0.0]);
    assert_eq!(status, GoalStatusEnum::Aborted);
    assert_eq!(
        r.error_code,
        error_code::GOAL_OUTSIDE_MAP,
        "{}",
        r.error_msg
    );
    assert!(r.error_msg.contains("off the map"), "{}", r.error_msg);
    // On the wall (column 20: x = 1.0 .. 1.1).
    let (status, r) = call(&client, [1.05, -0.5], goal);
    assert_eq!(status, GoalStatusEnum::Aborted);
    assert_eq!(r.error_code, error_code::START_OCCUPIED, "{}", r.error_msg);
}

#[test]
fn an_unreachable_device_is_an_error_to_the_caller() {
    let d = domain(1);
    // A local port nobody listens on.
    let port = std::net::TcpListener::bind("127.0.0.1:0")
        .and_then(|l| l.local_addr())
        .expect("a free port")
        .port();
    let _node = ohaca_ros(d, &["--tcp", &format!("127.0.0.1:{port}")]);
    let mut me = client_node(d);
    let map = map_publisher(&mut me);
    map.publish(map_message()).expect("publish the map");
    let client = action_client(&mut me);
    let (status, r) = call(&client, [-0.95, -0.95], [1.25, -0.95]);
    assert_eq!(status, GoalStatusEnum::Aborted);
    assert_eq!(r.error_code, error_code::UNKNOWN, "{}", r.error_msg);
    assert!(
        r.error_msg.contains("device unreachable") && r.error_msg.contains("cannot open"),
        "{}",
        r.error_msg
    );
}
