//! The navigation node: costmaps, planner, controller and executor behind ROS 2 topics
//! (`/goal_pose` + `/localization/pose` + `/points` + `/map` -> `/cmd_vel`, `/plan`,
//! `/navigate/status`), stepping its embedded localizer first unless configured apart.

use super::config::NavConfig;
use super::controller::Controller;
use super::costmap::GlobalCostmap;
use super::executor::{Executor, ExecutorStats, Goal, State, World};
use super::global_planner::{to_path_msg, GlobalPlanner, PlanError};
use super::local_costmap::LocalCostmap;
use super::localization::Localizer;
use super::map::StaticMap;
use super::{cloud, topics};
use agrisim_bus::Bus;
use agrisim_bus::Node;
use agrisim_error::Result;
use agrisim_math::pose2::Pose2;
use agrisim_msgs::agrisim::NavigationStatus;
use agrisim_msgs::builtin_interfaces::Time;
use agrisim_msgs::geometry_msgs::{PoseStamped, Twist, Vector3};
use agrisim_msgs::nav_msgs::OccupancyGrid;
use agrisim_msgs::sensor_msgs::PointCloud2;
use agrisim_msgs::std_msgs::Header;

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
    /// With the planner and controller `config.plugins` names.
    pub fn new(config: NavConfig) -> Navigator {
        Navigator::with_exec(config, Executor::new(&config))
    }

    /// With a planner and a controller of the caller's (`config.plugins` is not read).
    pub fn with(config: NavConfig, planner: Box<dyn GlobalPlanner>, controller: Box<dyn Controller>) -> Navigator {
        Navigator::with_exec(config, Executor::with(&config, planner, controller))
    }

    fn with_exec(config: NavConfig, exec: Executor) -> Navigator {
        Navigator {
            cfg: config,
            localizer: config.embedded_localizer.then(|| Localizer::new(&config)),
            seen: [0; 4],
            map: None,
            global: None,
            local: None,
            pose: None,
            exec,
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
    pub fn last_plan_error(&self) -> Option<PlanError> {
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
    Goal { pose: Pose2::from(&msg.pose), use_yaw: norm > 1e-6 && norm.is_finite() }
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
            self.pose = Some(Pose2::from(&p.pose));
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
            bus.publish(topics::PLAN, t_ns, &to_path_msg(plan, goal, &header));
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
