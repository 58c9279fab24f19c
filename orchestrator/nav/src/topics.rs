//! Topic names (ROS 2 / Nav2 conventions).

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
/// nav_msgs/OccupancyGrid costmaps, when enabled with
/// [`Navigator::publish_costmaps`](crate::Navigator::publish_costmaps).
pub const GLOBAL_COSTMAP: &str = "/global_costmap/costmap";
pub const LOCAL_COSTMAP: &str = "/local_costmap/costmap";
