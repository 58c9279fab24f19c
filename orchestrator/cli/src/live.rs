//! `--ros2`, `--external` and `--foxglove`: the command line of the live links. Which built-in
//! nodes an external node replaces, which topics the ROS 2 bridge takes from peers (the
//! system's commands, the replaced nodes' outputs, `--ros2-subscribe`), how it keeps time,
//! and where the Foxglove live view listens.

use agrisim_error::{err, Result};
use agrisim_ros2::names::Remap;
use agrisim_ros2::{BridgeConfig, Distro, Mode, Ros2Bridge, Stats, Topics};
use agrisim_session::run::{NodeFactory, NodePlan, SystemIo};
use std::collections::BTreeSet;
use std::sync::{Arc, Mutex};
use std::time::Duration;

#[derive(clap::Args, Clone, Debug)]
pub struct LiveArgs {
    /// Bridge the run to ROS 2 over DDS: every message of the bus is published (topics
    /// `rt/<name>`, types `pkg::msg::dds_::Type_`, raw CDR) with /clock, scalars as
    /// std_msgs/Float64, and the system's command topics and scalar inputs (plus the topics
    /// of `--external` nodes) are taken from ROS 2 peers.
    #[arg(long)]
    pub ros2: bool,
    /// Bridge the run to ROS 2 over Zenoh, in rmw_zenoh's format (peers with
    /// RMW_IMPLEMENTATION=rmw_zenoh_cpp): the same topics as --ros2, on keys
    /// `<domain>/<topic>/<type>/RIHS01_<hash>`, with liveliness tokens. The --ros2-* options
    /// (domain, mode, timeout, rate, remap, subscribe, lockstep, stats) apply to it too, also
    /// spelt --zenoh-*.
    #[arg(long, conflicts_with = "ros2")]
    pub zenoh: bool,
    /// Zenoh: endpoints to listen on ("none": no listener, e.g. beside a running rmw_zenohd).
    #[arg(long, value_name = "ENDPOINT", default_value = agrisim_zenoh::DEFAULT_LISTEN)]
    pub zenoh_listen: Vec<String>,
    /// Zenoh: endpoints to connect to (a router such as rmw_zenohd: tcp/127.0.0.1:7447).
    #[arg(long, value_name = "ENDPOINT")]
    pub zenoh_connect: Vec<String>,
    /// Zenoh session mode: peer, client or router (router: rmw_zenoh peers that want a
    /// router find one in the run).
    #[arg(long, value_name = "MODE", default_value = "peer", value_parser = ["peer", "client", "router"])]
    pub zenoh_session: String,
    /// Zenoh: find peers by multicast scouting on the LAN (off: only the endpoints above).
    #[arg(long)]
    pub zenoh_multicast: bool,
    /// DDS domain (ROS_DOMAIN_ID).
    #[arg(long, value_name = "ID", default_value_t = 0, env = "ROS_DOMAIN_ID", alias = "zenoh-domain")]
    pub ros2_domain: u16,
    /// lockstep: at each message instant wait for the peers' answers (deterministic);
    /// realtime: pace the simulation to the wall clock (as the paper ran).
    #[arg(long, value_name = "MODE", default_value = "lockstep", value_parser = ["lockstep", "realtime"], alias = "zenoh-mode")]
    pub ros2_mode: String,
    /// Lockstep: how long to wait for the answers at one instant [s, wall time].
    #[arg(long, value_name = "SECONDS", default_value_t = 1.0, alias = "zenoh-timeout")]
    pub ros2_timeout: f64,
    /// Lockstep: how long to wait for the peers before the first instant [s, wall time].
    #[arg(long, value_name = "SECONDS", default_value_t = 30.0, alias = "zenoh-startup-timeout")]
    pub ros2_startup_timeout: f64,
    /// Realtime: simulated seconds per wall second.
    #[arg(long, value_name = "FACTOR", default_value_t = 1.0, alias = "zenoh-rate")]
    pub ros2_rate: f64,
    /// Rename a topic on the ROS 2 side: FROM:=TO (e.g. /cmd_vel:=/robot/cmd_vel).
    #[arg(long = "ros2-remap", alias = "zenoh-remap", value_name = "FROM:=TO")]
    pub remap: Vec<String>,
    /// Also take TOPIC (of ROS 2 type pkg/msg/Type) from ROS 2 peers: TOPIC=TYPE.
    #[arg(long = "ros2-subscribe", alias = "zenoh-subscribe", value_name = "TOPIC=TYPE")]
    pub subscribe: Vec<String>,
    /// Lockstep waits for these topics (default: the replaced nodes' command outputs).
    #[arg(long = "ros2-lockstep", alias = "zenoh-lockstep", value_name = "TOPIC")]
    pub lockstep: Vec<String>,
    /// Talk on every network interface, not only loopback (exposes the run to the network).
    #[arg(long)]
    pub ros2_all_interfaces: bool,
    /// The peers' ROS 2 distro (humble, or iron/jazzy/kilted/rolling): the layout of the graph
    /// information that names the bridge's node in `ros2 node list`.
    #[arg(long, value_name = "DISTRO", default_value = "jazzy")]
    pub ros2_distro: String,
    /// Write the bridge's statistics to FILE (JSON): messages and bytes per topic, received,
    /// rejected, lockstep round trips [s].
    #[arg(long, value_name = "FILE", alias = "zenoh-stats")]
    pub ros2_stats: Option<std::path::PathBuf>,
    /// Turn off a built-in node so an external one (over --ros2) takes its place: navigator,
    /// harvest (told its fruit on /harvest/task; by sight its region on /harvest/task_region),
    /// command_script, odom_tf,
    /// robot_state_publisher, map_server, goal_publisher.
    #[arg(long = "external", value_name = "NODE")]
    pub external: Vec<String>,
    /// Serve the bus live to Foxglove (WebSocket, foxglove.sdk.v1) on ADDR (default
    /// 127.0.0.1:8765; give 0.0.0.0:PORT to expose it to the network).
    #[arg(long, value_name = "ADDR", num_args = 0..=1, default_missing_value = agrisim_foxglove::DEFAULT_ADDR)]
    pub foxglove: Option<String>,
    /// Pace the run to the wall clock, FACTOR simulated seconds per wall second (bare: 1,
    /// real time; 0.5: half speed), so a person can follow it in a viewer; with or without a
    /// bridge. It only waits: messages, recordings and results are the same without it.
    #[arg(long, value_name = "FACTOR", num_args = 0..=1, default_missing_value = "1")]
    pub realtime: Option<f64>,
}

/// A topic and its ROS 2 type.
type Topic = (&'static str, &'static str);

/// What a replaced built-in node published (its topics now come from ROS 2), and those
/// lockstep waits for: the external node answers each /clock tick with one message on each
/// (the navigator: a command and its status, as Nav2's controller and navigator do).
fn outputs_of(node: &str) -> Option<(&'static [Topic], &'static [&'static str])> {
    Some(match node {
        "navigator" => (
            &[
                ("/cmd_vel", "geometry_msgs/msg/Twist"),
                ("/navigate/status", "agrisim_msgs/msg/NavigationStatus"),
                ("/localization/pose", "geometry_msgs/msg/PoseStamped"),
                ("/plan", "nav_msgs/msg/Path"),
            ],
            &["/cmd_vel", "/navigate/status"],
        ),
        "command_script" => (&[("/cmd_vel", "geometry_msgs/msg/Twist")], &["/cmd_vel"]),
        // The harvest node's scalars (/lift/setpoint, /harvest/target_id) are system inputs,
        // taken anyway; it reports its status every tick.
        "harvest" => (
            &[
                ("/cmd_vel", "geometry_msgs/msg/Twist"),
                ("/left_arm/joint_trajectory", "trajectory_msgs/msg/JointTrajectory"),
                ("/right_arm/joint_trajectory", "trajectory_msgs/msg/JointTrajectory"),
                ("/left_gripper/command", "control_msgs/msg/GripperCommand"),
                ("/right_gripper/command", "control_msgs/msg/GripperCommand"),
                ("/harvest/status", "agrisim_msgs/msg/HarvestStatus"),
                ("/harvest/plans", "agrisim_msgs/msg/PlanResult"),
            ],
            &["/harvest/status"],
        ),
        "odom_tf" | "robot_state_publisher" => (&[("/tf", "tf2_msgs/msg/TFMessage")], &[]),
        "map_server" => (&[("/map", "nav_msgs/msg/OccupancyGrid")], &[]),
        "goal_publisher" => (&[("/goal_pose", "geometry_msgs/msg/PoseStamped")], &[]),
        _ => return None,
    })
}

impl LiveArgs {
    /// The run's node plan; `stats` collects each run's bridge statistics.
    pub fn plan(&self, stats: &Arc<Mutex<Vec<Arc<Mutex<Stats>>>>>) -> Result<NodePlan> {
        let plan = self.links(stats)?;
        let Some(factor) = self.realtime else { return Ok(plan) };
        agrisim_nodes::Pace::new(factor)?;
        // The pacer first among the extra nodes: the bridges send each instant when it is due.
        let links = plan.extra.clone();
        let extra: NodeFactory = Arc::new(move |io: &SystemIo| -> Result<Vec<Box<dyn agrisim_bus::Node>>> {
            let mut nodes: Vec<Box<dyn agrisim_bus::Node>> = vec![Box::new(agrisim_nodes::RealtimePacer::new(factor)?)];
            if let Some(links) = &links {
                nodes.extend(links(io)?);
            }
            Ok(nodes)
        });
        Ok(NodePlan { external: plan.external, extra: Some(extra) })
    }

    /// The node plan of the live links (bridges, external nodes).
    fn links(&self, stats: &Arc<Mutex<Vec<Arc<Mutex<Stats>>>>>) -> Result<NodePlan> {
        let external: BTreeSet<String> = self.external.iter().cloned().collect();
        let foxglove: Option<std::net::SocketAddr> = match &self.foxglove {
            Some(a) => Some(a.parse().map_err(|e| err!("--foxglove {a}: not an address IP:PORT ({e})"))?),
            None => None,
        };
        if !self.ros2 && !self.zenoh {
            if !external.is_empty() {
                return Err(err!("--external needs --ros2 or --zenoh (the external node talks to the run over ROS 2)"));
            }
            return Ok(match foxglove {
                Some(addr) => NodePlan {
                    external,
                    extra: Some(Arc::new(move |io: &SystemIo| Ok(vec![foxglove_view(addr, io)?]))),
                },
                None => NodePlan::default(),
            });
        }
        let mut extra_inbound: Vec<(String, String)> = vec![];
        let mut lockstep: Vec<String> = vec![];
        for name in &external {
            let (outs, answer) = outputs_of(name).ok_or_else(|| err!("--external {name}: not a node whose outputs the bridge knows (navigator, harvest, command_script, odom_tf, robot_state_publisher, map_server, goal_publisher)"))?;
            extra_inbound.extend(outs.iter().map(|(t, ty)| (t.to_string(), ty.to_string())));
            lockstep.extend(answer.iter().map(|t| t.to_string()));
        }
        for s in &self.subscribe {
            let (t, ty) = s.split_once('=').ok_or_else(|| err!("--ros2-subscribe {s}: expected TOPIC=pkg/msg/Type"))?;
            if !agrisim_msgs::dynamic::is_known(ty) {
                return Err(err!("--ros2-subscribe {s}: unknown message type {ty}"));
            }
            extra_inbound.push((t.to_string(), ty.to_string()));
        }
        if !self.lockstep.is_empty() {
            lockstep = self.lockstep.clone();
        }
        lockstep.sort();
        lockstep.dedup();
        let mode = match self.ros2_mode.as_str() {
            "realtime" if self.ros2_rate > 0.0 && self.ros2_rate.is_finite() => Mode::Realtime { rate: self.ros2_rate },
            "realtime" => return Err(err!("--ros2-rate {}: must be a positive number", self.ros2_rate)),
            _ if self.ros2_timeout > 0.0 && self.ros2_timeout.is_finite() => {
                Mode::Lockstep { timeout: Duration::from_secs_f64(self.ros2_timeout) }
            }
            _ => return Err(err!("--ros2-timeout {}: must be a positive number", self.ros2_timeout)),
        };
        let remap = Remap::parse(&self.remap).map_err(|e| err!("--ros2-remap: {e}"))?;
        let (domain, loopback_only) = (self.ros2_domain, !self.ros2_all_interfaces);
        if !(self.ros2_startup_timeout >= 0.0 && self.ros2_startup_timeout.is_finite()) {
            return Err(err!("--ros2-startup-timeout {}: must be a number of seconds", self.ros2_startup_timeout));
        }
        let startup_timeout = Duration::from_secs_f64(self.ros2_startup_timeout);
        let distro = Distro::parse(&self.ros2_distro).map_err(|e| err!("--ros2-distro: {e}"))?;
        let stats = stats.clone();
        let zenoh = self.zenoh.then(|| zenoh_options(self));
        let factory = move |inputs: &SystemIo| -> Result<Vec<Box<dyn agrisim_bus::Node>>> {
            let mut inbound: Vec<(String, String)> = inputs.messages.clone();
            for t in &extra_inbound {
                if !inbound.iter().any(|(i, _)| i == &t.0) {
                    inbound.push(t.clone());
                }
            }
            let topics = Topics {
                mode,
                inbound,
                inbound_scalars: inputs.scalars.clone(),
                outbound: inputs.outputs.clone(),
                lockstep: lockstep.clone(),
                remap: remap.clone(),
                startup_timeout,
            };
            let (bridge, s): (Box<dyn agrisim_bus::Node>, _) = match &zenoh {
                Some((listen, connect, session_mode, multicast_scouting)) => {
                    let config = agrisim_zenoh::ZenohConfig {
                        domain: domain.into(),
                        topics,
                        listen: listen.clone(),
                        connect: connect.clone(),
                        session_mode: session_mode.clone(),
                        multicast_scouting: *multicast_scouting,
                    };
                    let (bridge, s) = agrisim_zenoh::ZenohBridge::new(config)?;
                    (Box::new(bridge), s)
                }
                None => {
                    let config = BridgeConfig { domain, topics, loopback_only, distro };
                    let (bridge, s) = Ros2Bridge::new(config)?;
                    (Box::new(bridge), s)
                }
            };
            stats.lock().expect("stats lock").push(s);
            let mut nodes: Vec<Box<dyn agrisim_bus::Node>> = vec![bridge];
            if let Some(addr) = foxglove {
                nodes.push(foxglove_view(addr, inputs)?);
            }
            Ok(nodes)
        };
        Ok(NodePlan { external, extra: Some(Arc::new(factory)) })
    }
}

/// The Zenoh session's endpoints, mode and scouting (`--zenoh-listen none`: no listener).
fn zenoh_options(a: &LiveArgs) -> (Vec<String>, Vec<String>, String, bool) {
    let listen = a.zenoh_listen.iter().filter(|e| e.as_str() != "none").cloned().collect();
    (listen, a.zenoh_connect.clone(), a.zenoh_session.clone(), a.zenoh_multicast)
}

/// The Foxglove live view on `addr`, announced on stderr; the channels of the system's
/// topics and the viewer topics exist before a client can connect (see agrisim_foxglove).
fn foxglove_view(addr: std::net::SocketAddr, io: &SystemIo) -> Result<Box<dyn agrisim_bus::Node>> {
    let mut known: Vec<(String, String)> = io.outputs.iter().chain(&io.messages).cloned().collect();
    known.extend(agrisim_session::run::viewer_topics());
    let (view, port) = agrisim_foxglove::FoxgloveView::start_with(addr, &known)?;
    eprintln!("foxglove: ws://{}:{port} (open it in Foxglove: Open connection, Foxglove WebSocket)", addr.ip());
    Ok(Box::new(view))
}

/// All runs' bridge statistics summed (round trips concatenated).
fn total(stats: &Arc<Mutex<Vec<Arc<Mutex<Stats>>>>>) -> Option<Stats> {
    let all = stats.lock().expect("stats lock");
    if all.is_empty() {
        return None;
    }
    let mut t = Stats::default();
    for s in all.iter() {
        let s = s.lock().expect("stats lock");
        t.link = s.link;
        t.published += s.published;
        t.published_bytes += s.published_bytes;
        t.received += s.received;
        t.rejected += s.rejected;
        t.instants += s.instants;
        t.lockstep_timeouts += s.lockstep_timeouts;
        t.waited += s.waited;
        t.round_trips.extend(&s.round_trips);
        for (k, (n, b)) in &s.topics {
            let e = t.topics.entry(k.clone()).or_default();
            e.0 += n;
            e.1 += b;
        }
    }
    Some(t)
}

/// The q-quantile (nearest rank) of sorted `v` [ms].
fn quantile_ms(v: &[f64], q: f64) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    1e3 * v[((q * v.len() as f64).ceil() as usize).clamp(1, v.len()) - 1]
}

/// One line of bridge statistics for stderr, and the JSON file if asked for.
pub fn report(stats: &Arc<Mutex<Vec<Arc<Mutex<Stats>>>>>, file: Option<&std::path::Path>) -> Result<Option<String>> {
    let Some(mut t) = total(stats) else { return Ok(None) };
    t.round_trips.sort_by(f64::total_cmp);
    let rt = &t.round_trips;
    let (p50, p99, max) = (quantile_ms(rt, 0.5), quantile_ms(rt, 0.99), quantile_ms(rt, 1.0));
    if let Some(f) = file {
        let topics: serde_json::Map<String, serde_json::Value> =
            t.topics.iter().map(|(k, (n, b))| (k.clone(), serde_json::json!({"messages": n, "bytes": b}))).collect();
        let v = serde_json::json!({
            "link": t.link, "instants": t.instants, "published": t.published, "published_bytes": t.published_bytes,
            "received": t.received, "rejected": t.rejected, "lockstep_timeouts": t.lockstep_timeouts,
            "waited_s": t.waited, "round_trip_ms": {"n": rt.len(), "p50": p50, "p99": p99, "max": max}, "topics": topics,
        });
        std::fs::write(f, serde_json::to_string_pretty(&v).expect("plain value"))
            .map_err(|e| err!("cannot write {}: {e}", f.display()))?;
    }
    // Named by its link: "ROS 2 bridge: ..." (DDS) or "Zenoh bridge: ..." (one kind per run).
    let mut line = format!(
        "{}: {} instants, {} messages ({:.1} MB) published, {} received, {} rejected, {} lockstep timeouts, {:.2} s waiting",
        t.link,
        t.instants,
        t.published,
        t.published_bytes as f64 / 1e6,
        t.received,
        t.rejected,
        t.lockstep_timeouts,
        t.waited
    );
    if !rt.is_empty() {
        line += &format!("; round trip p50 {p50:.2} ms, p99 {p99:.2} ms, max {max:.2} ms");
    }
    Ok(Some(line))
}
