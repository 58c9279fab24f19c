//! The navigation stack, Nav2-shaped and speaking only ROS 2 messages, so real Nav2 nodes
//! can replace it piece by piece.
//!
//! Two nodes, which by default run as one (the navigator steps an embedded localizer first):
//! * [`Localizer`] (`localization.rs`): `/odom` + `/imu` + `/points` + `/map` ->
//!   `/tf` (map -> odom) and `/localization/pose`.
//! * [`Navigator`] (this file): `/goal_pose` + `/localization/pose` + `/points` + `/map` ->
//!   `/cmd_vel`, `/plan`, `/navigate/status`.
//!
//! With `embedded_localizer = false` they are separate nodes (run the localizer first, so the
//! navigator sees this instant's pose); the messages on the bus are the same either way.
//!
//! Inside, one concept per file: [`map`] (the OccupancyGrid), [`distance`] (exact distance
//! transform), [`costmap`] (global costmap, inflation), [`local_costmap`] (rolling window from
//! the LiDAR), [`footprint`], [`astar`] (global planner), [`tracking`] (progress along the
//! plan), [`dwa`] (local planner), [`scan_match`] + [`lidar_odometry`] + [`localization`],
//! [`executor`] (the goal's state machine), [`config`] (all parameters) and [`cloud`]
//! (PointCloud2 codec).
//! Deterministic: no clocks, no hash maps, no threads.

pub mod astar;
pub mod cloud;
pub mod config;
pub mod costmap;
pub mod distance;
pub mod dwa;
pub mod executor;
pub mod footprint;
pub mod lidar_odometry;
pub mod local_costmap;
pub mod localization;
pub mod map;
pub mod scan_match;
pub mod tracking;
pub mod turn_spot;

pub use config::NavConfig;
/// The name the benchmark harness uses for [`NavConfig`].
pub type NavigatorConfig = NavConfig;
pub use agrisim_math::pose2::{self, Pose2};
pub use executor::{ExecutorStats, Goal, State};
pub use localization::Localizer;

use agrisim_bus::Bus;
use agrisim_bus::Node;
use agrisim_error::Result;
use agrisim_msgs::agrisim::NavigationStatus;
use agrisim_msgs::builtin_interfaces::Time;
use agrisim_msgs::geometry_msgs::{PoseStamped, Twist, Vector3};
use agrisim_msgs::nav_msgs::OccupancyGrid;
use agrisim_msgs::sensor_msgs::PointCloud2;
use agrisim_msgs::std_msgs::Header;
use costmap::GlobalCostmap;
use executor::{Executor, World};
use local_costmap::LocalCostmap;
use map::StaticMap;

/// Topic names (ROS 2 / Nav2 conventions).
pub mod topics {
    /// nav_msgs/OccupancyGrid, the static map (published once, map_server style).
    pub const MAP: &str = "/map";
    /// nav_msgs/Odometry, odom -> base_link wheel odometry.
    pub const ODOM: &str = "/odom";
    /// sensor_msgs/Imu.
    pub const IMU: &str = "/imu";
    /// sensor_msgs/PointCloud2 in the LiDAR frame.
    pub const POINTS: &str = "/points";
    /// geometry_msgs/PoseStamped goals in the map frame.
    pub const GOAL: &str = "/goal_pose";
    /// geometry_msgs/PoseStamped, the localization estimate of base_link in map.
    pub const POSE: &str = "/localization/pose";
    /// tf2_msgs/TFMessage (map -> odom).
    pub const TF: &str = "/tf";
    /// geometry_msgs/Twist in base_link.
    pub const CMD_VEL: &str = "/cmd_vel";
    /// nav_msgs/Path, the global plan.
    pub const PLAN: &str = "/plan";
    /// agrisim_msgs/NavigationStatus.
    pub const STATUS: &str = "/navigate/status";
    /// nav_msgs/OccupancyGrid costmaps, when enabled with [`Navigator::publish_costmaps`].
    pub const GLOBAL_COSTMAP: &str = "/global_costmap/costmap";
    pub const LOCAL_COSTMAP: &str = "/local_costmap/costmap";
}

/// The navigation node: costmaps, planner, controller and executor behind ROS 2 topics.
pub struct Navigator {
    cfg: NavConfig,
    localizer: Option<Localizer>,
    seen: [u64; 4],
    map: Option<StaticMap>,
    global: Option<GlobalCostmap>,
    local: Option<LocalCostmap>,
    pose: Option<Pose2>,
    exec: Executor,
    goal_msg: PoseStamped,
    last_status: Option<(State, String)>,
    last_status_ns: i64,
    /// Publish the costmaps as OccupancyGrids at 1 Hz (for viewers; off by default).
    pub publish_costmaps: bool,
    last_costmap_ns: i64,
}

impl Navigator {
    pub fn new(config: NavConfig) -> Navigator {
        Navigator {
            cfg: config,
            localizer: config.embedded_localizer.then(|| Localizer::new(&config)),
            seen: [0; 4],
            map: None,
            global: None,
            local: None,
            pose: None,
            exec: Executor::new(&config),
            goal_msg: PoseStamped::default(),
            last_status: None,
            last_status_ns: i64::MIN,
            publish_costmaps: false,
            last_costmap_ns: i64::MIN,
        }
    }

    pub fn state(&self) -> State {
        self.exec.state()
    }

    pub fn detail(&self) -> &str {
        self.exec.detail()
    }

    pub fn stats(&self) -> ExecutorStats {
        self.exec.stats
    }

    /// Why the last "no_path" failure happened (goal blocked, start boxed in, unreachable...).
    pub fn last_plan_error(&self) -> Option<astar::PlanError> {
        self.exec.last_plan_error
    }

    /// The current plan (map frame).
    pub fn path(&self) -> &[(f64, f64)] {
        self.exec.path()
    }

    /// The embedded localizer, if any.
    pub fn localizer(&self) -> Option<&Localizer> {
        self.localizer.as_ref()
    }

    pub fn localizer_mut(&mut self) -> Option<&mut Localizer> {
        self.localizer.as_mut()
    }

    pub fn global_costmap(&self) -> Option<&GlobalCostmap> {
        self.global.as_ref()
    }

    pub fn local_costmap(&self) -> Option<&LocalCostmap> {
        self.local.as_ref()
    }

    fn set_map(&mut self, msg: &OccupancyGrid) -> Result<()> {
        let map = StaticMap::from_msg(msg, self.cfg.costmap.unknown_is_obstacle)?;
        let r = self.cfg.robot.footprint.inscribed_radius();
        self.global = Some(GlobalCostmap::new(&map, r, self.cfg.costmap.inflation));
        self.local = Some(LocalCostmap::new(self.cfg.costmap.local, &map.geom));
        self.map = Some(map);
        // A new map restarts planning for the goal in hand.
        self.exec.restart_planning();
        Ok(())
    }

    fn integrate_cloud(&mut self, cloud: &PointCloud2) -> Result<()> {
        let (Some(pose), Some(map), Some(local)) = (self.pose, self.map.as_ref(), self.local.as_mut()) else {
            return Ok(());
        };
        let mount = self.cfg.robot.lidar_mount;
        let pts = mount.transform_all(&cloud::decode_xyz(cloud)?);
        local.update(
            &pose,
            [mount.x, mount.y, mount.z],
            self.cfg.robot.base_link_height,
            &pts,
            map,
            &self.cfg.robot.footprint,
        );
        Ok(())
    }

    fn publish_status(&mut self, t_ns: i64, bus: &mut Bus) {
        let now = (self.exec.state(), self.exec.detail().to_string());
        let period = (self.cfg.executor.status_period * 1e9) as i64;
        if self.last_status.as_ref() == Some(&now) && t_ns - self.last_status_ns < period {
            return;
        }
        let msg = NavigationStatus {
            header: Header::new(Time::from_nanos(t_ns), "map"),
            state: now.0.as_str().to_string(),
            detail: now.1.clone(),
            goal: self.goal_msg.clone(),
        };
        bus.publish(topics::STATUS, t_ns, &msg);
        self.last_status = Some(now);
        self.last_status_ns = t_ns;
    }
}

/// A goal's orientation counts unless it is the zero quaternion (no heading requested).
fn goal_from_msg(msg: &PoseStamped) -> Goal {
    let q = &msg.pose.orientation;
    let norm = (q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w).sqrt();
    Goal { pose: Pose2::from_msg(&msg.pose), use_yaw: norm > 1e-6 && norm.is_finite() }
}

impl Node for Navigator {
    fn name(&self) -> &str {
        "navigator"
    }

    fn step(&mut self, t_ns: i64, bus: &mut Bus) -> Result<()> {
        if let Some(l) = self.localizer.as_mut() {
            l.step(t_ns, bus)?;
        }
        if let Some(m) = bus.take_new::<OccupancyGrid>(topics::MAP, &mut self.seen[0])? {
            self.set_map(&m)?;
        }
        if let Some(p) = bus.take_new::<PoseStamped>(topics::POSE, &mut self.seen[1])? {
            self.pose = Some(Pose2::from_msg(&p.pose));
        }
        if let Some(c) = bus.take_new::<PointCloud2>(topics::POINTS, &mut self.seen[2])? {
            self.integrate_cloud(&c)?;
        }
        if let Some(g) = bus.take_new::<PoseStamped>(topics::GOAL, &mut self.seen[3])? {
            let goal = goal_from_msg(&g);
            self.goal_msg = g.clone();
            if g.header.frame_id.is_empty() || g.header.frame_id == "map" {
                self.exec.set_goal(goal, t_ns);
            } else {
                self.exec.reject(goal, "goal frame must be map", t_ns);
            }
        }
        let world = match (self.global.as_mut(), self.local.as_mut()) {
            (Some(global), Some(local)) => Some(World { global, local }),
            _ => None,
        };
        let out = self.exec.tick(t_ns, self.pose, world);
        let header = Header::new(Time::from_nanos(t_ns), "map");
        if let Some(plan) = &out.plan {
            let goal = self.exec.goal().filter(|g| g.use_yaw).map(|g| g.pose.yaw);
            bus.publish(topics::PLAN, t_ns, &astar::to_path_msg(plan, goal, &header));
        }
        if let Some(v) = out.cmd {
            bus.publish(
                topics::CMD_VEL,
                t_ns,
                &Twist { linear: Vector3 { x: v.vx, y: v.vy, z: 0.0 }, angular: Vector3 { x: 0.0, y: 0.0, z: v.wz } },
            );
        }
        self.publish_status(t_ns, bus);
        if self.publish_costmaps && t_ns - self.last_costmap_ns >= 1_000_000_000 {
            if let (Some(g), Some(l)) = (&self.global, &self.local) {
                bus.publish(topics::GLOBAL_COSTMAP, t_ns, &g.to_msg("map", header.stamp));
                bus.publish(topics::LOCAL_COSTMAP, t_ns, &l.to_msg("map", header.stamp));
                self.last_costmap_ns = t_ns;
            }
        }
        Ok(())
    }
}
