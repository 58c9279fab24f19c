//! Every parameter of the navigation stack, grouped like the pieces that use them, with
//! defaults for the paper's robot (1.2 x 0.9 m omni base, LiDAR 1 m above base_link) in a
//! greenhouse with 2 m aisles. All structs read from TOML/JSON with missing fields defaulted.

use super::astar::PlannerConfig;
use super::costmap::InflationConfig;
use super::dwa::ControllerConfig;
use super::footprint::Footprint;
use super::lidar_odometry::LidarOdometryConfig;
use super::local_costmap::LocalCostmapConfig;
use super::plugins::Plugins;
use super::scan_match::ScanMatchConfig;
use serde::{Deserialize, Serialize};

/// Pose of a sensor in base_link (REP 103), roll-pitch-yaw as rotations about fixed x, y, z.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct SensorMount {
    pub x: f64,
    pub y: f64,
    pub z: f64,
    pub roll: f64,
    pub pitch: f64,
    pub yaw: f64,
}

impl Default for SensorMount {
    fn default() -> Self {
        SensorMount { x: 0.0, y: 0.0, z: 1.0, roll: 0.0, pitch: 0.0, yaw: 0.0 }
    }
}

impl SensorMount {
    /// Rotation (row-major, R = Rz(yaw) Ry(pitch) Rx(roll)) and translation, sensor to base.
    pub fn matrix(&self) -> ([[f64; 3]; 3], [f64; 3]) {
        let (sr, cr) = self.roll.sin_cos();
        let (sp, cp) = self.pitch.sin_cos();
        let (sy, cy) = self.yaw.sin_cos();
        (
            [
                [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
                [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
                [-sp, cp * sr, cp * cr],
            ],
            [self.x, self.y, self.z],
        )
    }

    /// A sensor-frame point in base_link.
    pub fn to_base(&self, p: [f32; 3]) -> [f32; 3] {
        self.transform_all(&[p])[0]
    }

    /// Sensor-frame points in base_link (the rotation computed once).
    pub fn transform_all(&self, pts: &[[f32; 3]]) -> Vec<[f32; 3]> {
        let (r, t) = self.matrix();
        pts.iter()
            .map(|p| {
                let (x, y, z) = (p[0] as f64, p[1] as f64, p[2] as f64);
                [
                    (r[0][0] * x + r[0][1] * y + r[0][2] * z + t[0]) as f32,
                    (r[1][0] * x + r[1][1] * y + r[1][2] * z + t[1]) as f32,
                    (r[2][0] * x + r[2][1] * y + r[2][2] * z + t[2]) as f32,
                ]
            })
            .collect()
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct RobotConfig {
    pub footprint: Footprint,
    pub lidar_mount: SensorMount,
    /// Height of base_link above the floor [m] (height bands are measured from the floor).
    pub base_link_height: f64,
}

impl Default for RobotConfig {
    fn default() -> Self {
        RobotConfig { footprint: Footprint::default(), lidar_mount: SensorMount::default(), base_link_height: 0.0 }
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct CostmapConfig {
    pub inflation: InflationConfig,
    pub local: LocalCostmapConfig,
    /// Treat unknown (-1) map cells as obstacles.
    pub unknown_is_obstacle: bool,
}

impl Default for CostmapConfig {
    fn default() -> Self {
        CostmapConfig {
            inflation: InflationConfig::default(),
            local: LocalCostmapConfig::default(),
            unknown_is_obstacle: true,
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct LocalizationConfig {
    /// The predefined start pose of base_link in the map (x, y, yaw) [m, m, rad].
    pub initial_pose: [f64; 3],
    /// Its standard deviations [m, m, rad].
    pub initial_std: [f64; 3],
    /// Time between scan matches [s] (matches run on the next cloud after it).
    pub scan_period: f64,
    /// Height band (above the floor) of the horizontal slice matched against the 2-D map [m];
    /// keep it inside the band the map was rasterized from.
    pub slice_min_z: f64,
    pub slice_max_z: f64,
    /// Range band of the points used [m].
    pub min_range: f64,
    pub max_range: f64,
    /// 2-D voxel size of the downsampling and the most points kept.
    pub voxel: f64,
    pub max_points: usize,
    pub matcher: ScanMatchConfig,
    /// Odometry noise: translation std per metre and per radian, rotation std per radian
    /// and per metre (the odometry motion model of Probabilistic Robotics, §5.4).
    pub odom_alpha: [f64; 4],
    /// Weight of the IMU yaw rate against the odometry's heading change (0..1).
    pub imu_weight: f64,
    /// Mahalanobis gate on scan-match innovations (chi-square, 3 dof) for matches with
    /// fewer than `trusted_inliers` of their points on the map; after `max_rejections` in a
    /// row the next match is taken anyway.
    pub gate: f64,
    pub trusted_inliers: f64,
    pub max_rejections: usize,
    /// Largest factor by which one inconsistent scan match inflates the covariance.
    pub max_inflation: f64,
    /// Motion from the slices registered against each other (fused with the wheels').
    pub lidar_odometry: LidarOdometryConfig,
}

impl Default for LocalizationConfig {
    fn default() -> Self {
        LocalizationConfig {
            initial_pose: [0.0; 3],
            initial_std: [0.05, 0.05, 0.02],
            scan_period: 0.2,
            slice_min_z: 0.2,
            slice_max_z: 1.5,
            min_range: 0.3,
            max_range: 25.0,
            voxel: 0.1,
            max_points: 500,
            matcher: ScanMatchConfig::default(),
            odom_alpha: [0.05, 0.02, 0.05, 0.02],
            imu_weight: 1.0,
            gate: 30.0,
            trusted_inliers: 0.6,
            max_rejections: 5,
            max_inflation: 25.0,
            lidar_odometry: LidarOdometryConfig::default(),
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct ExecutorConfig {
    /// Goal reached when the base centre is within this of the goal [m] (Nav2's 0.25).
    pub xy_goal_tolerance: f64,
    /// The controller keeps driving until this close before it latches the goal position
    /// and starts the rotate phase (hysteresis: it only resumes translating beyond
    /// `xy_goal_tolerance`) [m].
    pub xy_latch_tolerance: f64,
    /// Yaw tolerance when the goal asks for a heading [rad]; `None` ignores goal yaw.
    pub yaw_goal_tolerance: Option<f64>,
    /// Within this distance of the goal the controller already aims for the goal yaw [m].
    pub goal_heading_distance: f64,
    /// Progress check: the robot must move this far ... [m]
    pub progress_radius: f64,
    /// ... within this long, else it is stuck [s].
    pub progress_timeout: f64,
    /// Recoveries (clear local costmap, back off, replan) before failing with "stuck".
    pub max_recoveries: usize,
    pub backup_speed: f64,
    pub backup_time: f64,
    /// Replan when the robot is farther than this from its path [m].
    pub max_path_deviation: f64,
    /// How far ahead along the path sensed obstacles are checked [m].
    pub blocked_lookahead: f64,
    /// Minimum time between replans [s].
    pub replan_interval: f64,
    /// Replan also at this period while following (0: only on events) [s].
    pub periodic_replan: f64,
    /// Status is republished at this period besides on change [s].
    pub status_period: f64,
    /// After finishing, zero twists are published for this long [s].
    pub stop_publish_time: f64,
    /// Fail with "timeout" after this long on one goal (0: never) [s].
    pub goal_timeout: f64,
}

impl Default for ExecutorConfig {
    fn default() -> Self {
        ExecutorConfig {
            xy_goal_tolerance: 0.25,
            xy_latch_tolerance: 0.08,
            yaw_goal_tolerance: Some(0.1),
            goal_heading_distance: 1.0,
            progress_radius: 0.25,
            progress_timeout: 8.0,
            max_recoveries: 3,
            backup_speed: 0.15,
            backup_time: 2.0,
            max_path_deviation: 0.6,
            blocked_lookahead: 8.0,
            replan_interval: 1.0,
            periodic_replan: 0.0,
            status_period: 1.0,
            stop_publish_time: 1.0,
            goal_timeout: 0.0,
        }
    }
}

/// The whole stack's configuration.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct NavConfig {
    /// The [`Navigator`](super::Navigator) runs a [`Localizer`](super::Localizer) itself, just
    /// before its own step. Set false to run localization as a separate node (or replace it,
    /// e.g. by AMCL through a bridge): the navigator then only reads `/localization/pose`.
    pub embedded_localizer: bool,
    /// The global planner and the controller by name (`[plugins]`: A* and DWA by default).
    pub plugins: Plugins,
    pub robot: RobotConfig,
    pub costmap: CostmapConfig,
    pub planner: PlannerConfig,
    pub controller: ControllerConfig,
    pub localization: LocalizationConfig,
    pub executor: ExecutorConfig,
}

impl Default for NavConfig {
    fn default() -> Self {
        NavConfig {
            embedded_localizer: true,
            plugins: Plugins::default(),
            robot: RobotConfig::default(),
            costmap: CostmapConfig::default(),
            planner: PlannerConfig::default(),
            controller: ControllerConfig::default(),
            localization: LocalizationConfig::default(),
            executor: ExecutorConfig::default(),
        }
    }
}

impl NavConfig {
    /// Defaults with the localizer starting at the predefined start pose (x, y, yaw).
    pub fn for_start(start: [f64; 3]) -> NavConfig {
        let mut c = NavConfig::default();
        c.localization.initial_pose = start;
        c
    }

    /// Defaults with the localizer starting from an estimate of the start pose whose error
    /// has standard deviations `std` [m, m, rad] (at least the default initial spread).
    pub fn for_estimate(estimate: [f64; 3], std: [f64; 3]) -> NavConfig {
        let mut c = NavConfig::for_start(estimate);
        let s = &mut c.localization.initial_std;
        *s = [s[0].max(std[0]), s[1].max(std[1]), s[2].max(std[2])];
        c
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mount_transform() {
        let m = SensorMount { x: 0.2, y: 0.0, z: 1.0, roll: 0.0, pitch: 0.0, yaw: std::f64::consts::FRAC_PI_2 };
        let p = m.to_base([1.0, 0.0, 0.0]);
        assert!((p[0] - 0.2).abs() < 1e-6 && (p[1] - 1.0).abs() < 1e-6 && (p[2] - 1.0).abs() < 1e-6);
        let m = SensorMount { pitch: std::f64::consts::FRAC_PI_2, ..SensorMount::default() };
        let p = m.to_base([1.0, 0.0, 0.0]);
        assert!((p[2] - 0.0).abs() < 1e-6 && p[0].abs() < 1e-6);
    }

    #[test]
    fn partial_toml_fills_defaults() {
        let c: NavConfig =
            toml::from_str("[localization]\ninitial_pose = [1.0, 2.0, 0.5]\n[controller]\nmax_vx = 0.4\n").unwrap();
        assert_eq!(c.localization.initial_pose, [1.0, 2.0, 0.5]);
        assert_eq!(c.controller.max_vx, 0.4);
        assert_eq!(c.controller.max_vy, 0.8);
        assert_eq!(c.executor.xy_goal_tolerance, 0.25);
        assert_eq!(c.plugins, Plugins::default());
        let c: NavConfig = toml::from_str("[plugins]\nplanner = \"straight_line\"\n").unwrap();
        assert_eq!(c.plugins.planner, crate::plugins::PlannerKind::StraightLine);
    }
}
