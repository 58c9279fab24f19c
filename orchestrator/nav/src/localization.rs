//! Localization without ground truth: an extended Kalman filter over the map pose
//! (x, y, yaw) of base_link. Prediction from wheel odometry increments (translation) and the
//! IMU yaw rate (heading: wheel slip corrupts the odometry's heading most), replaced at every
//! scan by that increment fused with the LiDAR odometry's
//! ([`lidar_odometry`](super::lidar_odometry): the slice registered against the robot's own
//! recent slices, which sees the wheels slip where the map has no feature); correction by
//! matching a horizontal slice of the LiDAR cloud against the static map
//! ([`scan_match`](super::scan_match)) a few times a second, weighted by the match's own
//! covariance. Publishes what a ROS localization node does: map -> odom on `/tf` and the pose
//! on `/localization/pose`.
//!
//! The filter is the textbook EKF (Thrun, Burgard, Fox, "Probabilistic Robotics", §3.3 and
//! the odometry motion model of §5.4), with a Mahalanobis gate on the scan-match innovation.

use super::config::{LocalizationConfig, NavConfig, RobotConfig};
use super::lidar_odometry::{Increment, LidarOdometry};
use super::scan_match::{correlative_match, LikelihoodField, Match};
use super::{cloud, map::StaticMap, topics};
use agrisim_bus::Node;
use agrisim_bus::{Bus, Reader};
use agrisim_error::Result;
use agrisim_math::pose2::{wrap_angle, Pose2};
use agrisim_msgs::builtin_interfaces::Time;
use agrisim_msgs::geometry_msgs::{self, PoseStamped, Transform, TransformStamped};
use agrisim_msgs::nav_msgs::{OccupancyGrid, Odometry};
use agrisim_msgs::sensor_msgs::{Imu, PointCloud2};
use agrisim_msgs::std_msgs::Header;
use agrisim_msgs::tf2_msgs::TFMessage;
use nalgebra::{Matrix3, Vector3};
use std::collections::VecDeque;

/// `a p aᵀ + b r bᵀ`: a covariance `p` through the linear map `a`, plus noise `r` entering
/// through `b` (EKF prediction; Joseph-form update).
fn propagate(a: &Matrix3<f64>, p: &Matrix3<f64>, b: &Matrix3<f64>, r: &Matrix3<f64>) -> Matrix3<f64> {
    a * p * a.transpose() + b * r * b.transpose()
}

/// Adjugate over determinant; `None` when (nearly) singular.
///
/// The adjugate stays hand-written: nalgebra's `try_inverse` computes entry (1, 0) as
/// `-(a10 a22 - a20 a12) / det`, which differs from `(a12 a20 - a10 a22) / det` in the sign
/// of a zero, and refuses only `det == 0`; the logs must stay bit-identical.
fn inverse(a: &Matrix3<f64>) -> Option<Matrix3<f64>> {
    let det = a.determinant();
    if det.abs() < 1e-300 {
        return None;
    }
    // Entry (i, j) is the cofactor of (j, i).
    Some(Matrix3::from_fn(|i, j| {
        let (i1, i2, j1, j2) = ((j + 1) % 3, (j + 2) % 3, (i + 1) % 3, (i + 2) % 3);
        (a[(i1, j1)] * a[(i2, j2)] - a[(i1, j2)] * a[(i2, j1)]) / det
    }))
}

/// The normalized innovation squared `yᵀ s y`, summed row by row of `(y_i s_ij) y_j`; kept in
/// this order (`y.dot(&(s * y))` groups the products differently and changes the last bits).
fn nis(y: &Vector3<f64>, s: &Matrix3<f64>) -> f64 {
    (0..3).map(|i| (0..3).map(|j| y[i] * s[(i, j)] * y[j]).sum::<f64>()).sum()
}

/// EKF update with H = I: the state correction and the Joseph-form covariance (which keeps it
/// symmetric positive definite), from the innovation `y`, the inverse innovation covariance
/// `si` and the measurement covariance `r`.
fn update(cov: &Matrix3<f64>, si: &Matrix3<f64>, y: &Vector3<f64>, r: &Matrix3<f64>) -> (Vector3<f64>, Matrix3<f64>) {
    let k = cov * si;
    (k * y, propagate(&(Matrix3::identity() - k), cov, &k, r))
}

fn diag(a: f64, b: f64, c: f64) -> Matrix3<f64> {
    Matrix3::from_diagonal(&Vector3::new(a, b, c))
}

/// The information-weighted mean of two measurements of one increment, the wheels' and the
/// LiDAR odometry's (yaw taken relative to the wheels', so no wrap sits between them), and
/// its covariance. `None` when a covariance is singular.
fn fuse(wheel: &Pose2, q_wheel: &Matrix3<f64>, lidar: &Increment) -> Option<(Pose2, Matrix3<f64>)> {
    let (a, b) = (inverse(q_wheel)?, inverse(&lidar.cov)?);
    let p = inverse(&(a + b))?;
    let dw = Vector3::new(wheel.x, wheel.y, wheel.yaw);
    let dl = Vector3::new(lidar.delta.x, lidar.delta.y, wheel.yaw + wrap_angle(lidar.delta.yaw - wheel.yaw));
    let d = p * (a * dw + b * dl);
    Some((Pose2::new(d[0], d[1], wrap_angle(d[2])), p))
}

/// Counters for tests and logs.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct LocalizerStats {
    pub predictions: u64,
    pub matches: u64,
    pub rejected: u64,
    pub failed: u64,
    /// Updates that inflated the covariance (odometry inconsistent with the scans).
    pub inflations: u64,
    /// Predictions from a LiDAR odometry increment (fused with the wheels').
    pub lidar_odometry: u64,
}

pub struct Localizer {
    cfg: LocalizationConfig,
    robot: RobotConfig,
    /// Last map and point cloud taken (the newest is enough for both).
    seen: [u64; 2],
    imu: Reader,
    odom: Reader,
    /// Gyro yaw-rate samples (stamp [ns], rate [rad/s]) not yet integrated; the last one is
    /// kept to hold its rate over the time after it.
    gyro: VecDeque<(i64, f64)>,
    field: Option<LikelihoodField>,
    mean: Pose2,
    cov: Matrix3<f64>,
    last_odom: Option<(i64, Pose2)>,
    gyro_bias: f64,
    last_match_ns: Option<i64>,
    rejections: usize,
    lidar_odometry: Option<LidarOdometry>,
    /// The filter's state just after the last scan, and the wheel (+ gyro) increment since:
    /// the prediction the next scan's LiDAR odometry replaces.
    anchor: Option<(Pose2, Matrix3<f64>)>,
    since_scan: Pose2,
    pub stats: LocalizerStats,
    /// The latest scan match (accepted or not), for diagnostics.
    pub last_match: Option<Match>,
}

impl Localizer {
    pub fn new(config: &NavConfig) -> Localizer {
        let cfg = config.localization;
        let [x, y, yaw] = cfg.initial_pose;
        let [sx, sy, sa] = cfg.initial_std;
        Localizer {
            cfg,
            robot: config.robot,
            seen: [0; 2],
            imu: Reader::new(topics::IMU),
            odom: Reader::new(topics::ODOM),
            gyro: VecDeque::new(),
            field: None,
            mean: Pose2::new(x, y, yaw),
            cov: diag(sx * sx, sy * sy, sa * sa),
            last_odom: None,
            gyro_bias: 0.0,
            last_match_ns: None,
            rejections: 0,
            lidar_odometry: cfg.lidar_odometry.enabled.then(|| LidarOdometry::new(cfg.lidar_odometry)),
            anchor: None,
            since_scan: Pose2::default(),
            stats: LocalizerStats::default(),
            last_match: None,
        }
    }

    /// The map pose estimate of base_link.
    pub fn pose(&self) -> Pose2 {
        self.mean
    }

    pub fn covariance(&self) -> Matrix3<f64> {
        self.cov
    }

    /// Restarts from a known pose (e.g. a trial's predefined initial state).
    pub fn reset(&mut self, pose: Pose2) {
        let [sx, sy, sa] = self.cfg.initial_std;
        self.mean = pose;
        self.cov = diag(sx * sx, sy * sy, sa * sa);
        self.rejections = 0;
        self.anchor = None;
    }

    pub fn set_map(&mut self, map: &StaticMap) {
        self.field = Some(LikelihoodField::new(map, &self.cfg.matcher));
    }

    /// Covariance of a wheel (+ gyro) increment `d`: the odometry motion model.
    fn odometry_noise(&self, d: &Pose2) -> Matrix3<f64> {
        let [a1, a2, a3, a4] = self.cfg.odom_alpha;
        let trans = d.x.hypot(d.y);
        let rot = d.yaw.abs();
        let st = a1 * trans + a2 * rot + 1e-4;
        let sr = a3 * rot + a4 * trans + 1e-5;
        diag(st * st, st * st, sr * sr)
    }

    /// Moves the estimate by a wheel (+ gyro) increment (EKF prediction).
    fn predict(&mut self, d: &Pose2) {
        let q = self.odometry_noise(d);
        self.predict_with(d, &q);
        self.since_scan = self.since_scan.compose(d);
    }

    /// Moves the estimate by a base-frame increment `d` with covariance `q`.
    fn predict_with(&mut self, d: &Pose2, q: &Matrix3<f64>) {
        let (s, c) = self.mean.yaw.sin_cos();
        let f = Matrix3::new(1.0, 0.0, -s * d.x - c * d.y, 0.0, 1.0, c * d.x - s * d.y, 0.0, 0.0, 1.0);
        let g = Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0);
        self.cov = propagate(&f, &self.cov, &g, q);
        self.mean = self.mean.compose(d);
        self.stats.predictions += 1;
    }

    /// Registers the slice with the LiDAR odometry and, when it measured the motion since the
    /// last scan, redoes that prediction from the state then with the wheel and LiDAR
    /// increments fused. The wheels' increment is charged the motion model's noise over the
    /// whole interval (not per odometry message): slip is a bias, not white noise, so the
    /// LiDAR odometry is believed wherever it sees structure.
    fn lidar_odometry(&mut self, pts: &[(f64, f64)], dense: &[(f64, f64)]) {
        let wheel = std::mem::take(&mut self.since_scan);
        let anchor = self.anchor.take();
        let Some(inc) = self.lidar_odometry.as_mut().and_then(|lo| lo.register(pts, dense, &wheel)) else { return };
        let Some((mean, cov)) = anchor else { return };
        let q_wheel = self.odometry_noise(&wheel);
        let Some((d, q)) = fuse(&wheel, &q_wheel, &inc) else { return };
        (self.mean, self.cov) = (mean, cov);
        self.predict_with(&d, &q);
        self.stats.lidar_odometry += 1;
    }

    /// Fuses a scan match (EKF update with H = I); false if gated out.
    ///
    /// Innovations larger than their covariance explains mean the odometry is worse than
    /// modelled (wheels slipping against an obstacle, on a wet floor): the predicted
    /// covariance is then inflated by the excess (covariance matching, as in adaptive
    /// Kalman filtering, e.g. Mohamed and Schwarz, J. Geodesy 73, 1999) so the filter follows
    /// the scans instead of lagging behind a biased odometry.
    fn correct(&mut self, m: &Match) -> bool {
        let y = Vector3::new(m.pose.x - self.mean.x, m.pose.y - self.mean.y, wrap_angle(m.pose.yaw - self.mean.yaw));
        let gate = |cov: &Matrix3<f64>| -> Option<(f64, Matrix3<f64>)> {
            let si = inverse(&(cov + m.cov))?;
            Some((nis(&y, &si), si))
        };
        let Some((d2, _)) = gate(&self.cov) else { return false };
        // Only doubtful matches are gated: one whose points mostly lie on mapped structure is
        // believed even when it contradicts slipping odometry.
        if d2 > self.cfg.gate && m.inliers < self.cfg.trusted_inliers && self.rejections < self.cfg.max_rejections {
            self.rejections += 1;
            self.stats.rejected += 1;
            return false;
        }
        self.rejections = 0;
        // Expected NIS is 3 (3 dof); inflate beyond twice that.
        if d2 > 6.0 {
            let f = (d2 / 6.0).min(self.cfg.max_inflation);
            self.cov *= f;
            self.stats.inflations += 1;
        }
        let Some((_, si)) = gate(&self.cov) else { return false };
        let (dx, cov) = update(&self.cov, &si, &y, &m.cov);
        self.mean = Pose2::new(self.mean.x + dx[0], self.mean.y + dx[1], wrap_angle(self.mean.yaw + dx[2]));
        self.cov = cov;
        self.stats.matches += 1;
        true
    }

    /// The horizontal slice of a cloud as base-frame 2-D points, downsampled on a voxel grid.
    pub fn slice(&self, cloud: &PointCloud2) -> Result<Vec<(f64, f64)>> {
        Ok(self.thin(&self.dense_slice(cloud)?))
    }

    /// At most `max_points` of a dense slice, evenly through its voxel order.
    fn thin(&self, dense: &[(f64, f64)]) -> Vec<(f64, f64)> {
        let stride = dense.len().div_ceil(self.cfg.max_points.max(1)).max(1);
        dense.iter().copied().step_by(stride).collect()
    }

    /// The slice with one point per voxel (every voxel kept).
    fn dense_slice(&self, cloud: &PointCloud2) -> Result<Vec<(f64, f64)>> {
        let pts = cloud::decode_xyz(cloud)?;
        let c = &self.cfg;
        let fp = &self.robot.footprint;
        let mount = &self.robot.lidar_mount;
        let mut keyed: Vec<((i64, i64), (f64, f64))> = Vec::with_capacity(pts.len() / 4);
        for b in mount.transform_all(&pts) {
            let z = b[2] as f64 + self.robot.base_link_height;
            if z < c.slice_min_z || z > c.slice_max_z {
                continue;
            }
            let (bx, by) = (b[0] as f64, b[1] as f64);
            let r = (bx - mount.x).hypot(by - mount.y);
            if r < c.min_range || r > c.max_range || fp.contains(bx, by, 0.05) {
                continue;
            }
            keyed.push((((bx / c.voxel).floor() as i64, (by / c.voxel).floor() as i64), (bx, by)));
        }
        // First point per voxel (stable sort: deterministic for a given cloud).
        keyed.sort_by_key(|k| k.0);
        keyed.dedup_by_key(|k| k.0);
        Ok(keyed.into_iter().map(|k| k.1).collect())
    }

    /// The yaw the gyro measured from `t0` to `t1` [ns] and the mean rate of its samples
    /// there. A sample stands for the rate over the interval that ends at its stamp (from the
    /// sample before, or `t0`); the newest one's rate is held on to `t1`. None without a
    /// sample in the interval. Consumes the samples up to `t1`.
    fn integrate_gyro(&mut self, t0: i64, t1: i64) -> Option<(f64, f64)> {
        while self.gyro.front().is_some_and(|s| s.0 <= t0) {
            self.gyro.pop_front();
        }
        let (mut turned, mut from, mut sum, mut n, mut last) = (0.0, t0, 0.0, 0usize, None);
        while let Some(&(stamp, w)) = self.gyro.front().filter(|s| s.0 <= t1) {
            turned += w * (stamp - from) as f64 * 1e-9;
            (from, sum, n, last) = (stamp, sum + w, n + 1, Some(w));
            self.gyro.pop_front();
        }
        let w = last?;
        turned += w * (t1 - from) as f64 * 1e-9;
        Some((turned, sum / n as f64))
    }

    fn publish(&self, t_ns: i64, odom: &Pose2, bus: &mut Bus) {
        let stamp = Time::from_nanos(t_ns);
        let pose = PoseStamped { header: Header::new(stamp, "map"), pose: self.mean.into() };
        bus.publish(topics::POSE, t_ns, &pose);
        let map_odom = self.mean.compose(&odom.inverse());
        let q = geometry_msgs::Pose::from(map_odom).orientation;
        let tf = TransformStamped {
            header: Header::new(stamp, "map"),
            child_frame_id: "odom".into(),
            transform: Transform {
                translation: geometry_msgs::Vector3 { x: map_odom.x, y: map_odom.y, z: 0.0 },
                rotation: q,
            },
        };
        bus.publish(topics::TF, t_ns, &TFMessage { transforms: vec![tf] });
    }
}

impl Node for Localizer {
    fn name(&self) -> &str {
        "localization"
    }

    fn step(&mut self, t_ns: i64, bus: &mut Bus) -> Result<()> {
        if let Some(m) = bus.take_new::<OccupancyGrid>(topics::MAP, &mut self.seen[0])? {
            self.set_map(&StaticMap::from_msg(&m, true)?);
        }
        for imu in self.imu.take::<Imu>(bus)? {
            self.gyro.push_back((imu.header.stamp.to_nanos(), imu.angular_velocity.z));
        }
        let mut odom_pose = None;
        for o in self.odom.take::<Odometry>(bus)? {
            let stamp = o.header.stamp.to_nanos();
            let stamp = if stamp > 0 { stamp } else { t_ns };
            let cur = Pose2::from(&o.pose.pose);
            let tw = &o.twist.twist;
            if let Some((t_prev, prev)) = self.last_odom {
                let mut d = prev.inverse().compose(&cur);
                let dt = (stamp - t_prev) as f64 * 1e-9;
                if let (Some((turned, mean)), true) = (self.integrate_gyro(t_prev, stamp), dt > 0.0) {
                    let still =
                        tw.linear.x.hypot(tw.linear.y) < 0.01 && tw.angular.z.abs() < 0.01 && d.x.hypot(d.y) < 1e-3;
                    if still {
                        self.gyro_bias += 0.1 * (mean - self.gyro_bias);
                    }
                    let d_imu = if still { 0.0 } else { turned - self.gyro_bias * dt };
                    d.yaw = self.cfg.imu_weight * d_imu + (1.0 - self.cfg.imu_weight) * d.yaw;
                }
                self.predict(&d);
            }
            self.last_odom = Some((stamp, cur));
            odom_pose = Some(cur);
        }
        let due = self.last_match_ns.is_none_or(|t| t_ns - t >= (self.cfg.scan_period * 1e9) as i64 - 1_000_000);
        if let Some(cloud) = bus.take_new::<PointCloud2>(topics::POINTS, &mut self.seen[1])? {
            if due && self.field.is_some() && self.last_odom.is_some() {
                self.last_match_ns = Some(t_ns);
                let dense = self.dense_slice(&cloud)?;
                let pts = self.thin(&dense);
                self.lidar_odometry(&pts, &dense);
                let field = self.field.as_ref().unwrap();
                let mut mcfg = self.cfg.matcher;
                // Widen the search when the estimate is uncertain (3 sigma), within reason.
                let sxy = self.cov[(0, 0)].max(self.cov[(1, 1)]).sqrt();
                mcfg.search_xy = mcfg.search_xy.max((3.0 * sxy).min(1.0));
                mcfg.search_yaw = mcfg.search_yaw.max((3.0 * self.cov[(2, 2)].sqrt()).min(0.3));
                match (pts.len() >= 20).then(|| correlative_match(field, &pts, &self.mean, &mcfg)).flatten() {
                    Some(m) => {
                        self.last_match = Some(m);
                        self.correct(&m);
                    }
                    None => self.stats.failed += 1,
                }
                self.anchor = Some((self.mean, self.cov));
            }
        }
        if let Some(op) = odom_pose {
            self.publish(t_ns, &op, bus);
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use agrisim_math::rng::Rng;

    #[test]
    fn matrix_inverse() {
        let a = Matrix3::new(4.0, 1.0, 0.5, 1.0, 3.0, 0.2, 0.5, 0.2, 2.0);
        assert!((a * inverse(&a).unwrap() - Matrix3::identity()).abs().max() < 1e-12);
        assert!(inverse(&Matrix3::new(1.0, 2.0, 3.0, 2.0, 4.0, 6.0, 0.0, 0.0, 1.0)).is_none());
    }

    /// The hand-written row-major algebra nalgebra replaced, kept as the reference the
    /// localizer's results are pinned to (benchmark logs are compared byte by byte).
    mod reference {
        pub type M3 = [[f64; 3]; 3];

        pub fn mul(a: &M3, b: &M3) -> M3 {
            std::array::from_fn(|i| std::array::from_fn(|j| (0..3).map(|k| a[i][k] * b[k][j]).sum()))
        }

        pub fn transpose(a: &M3) -> M3 {
            std::array::from_fn(|i| std::array::from_fn(|j| a[j][i]))
        }

        pub fn add(a: &M3, b: &M3) -> M3 {
            std::array::from_fn(|i| std::array::from_fn(|j| a[i][j] + b[i][j]))
        }

        pub fn inverse(a: &M3) -> Option<M3> {
            let det = a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1])
                - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0])
                + a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
            if det.abs() < 1e-300 {
                return None;
            }
            Some(std::array::from_fn(|i| {
                std::array::from_fn(|j| {
                    let (i1, i2, j1, j2) = ((j + 1) % 3, (j + 2) % 3, (i + 1) % 3, (i + 2) % 3);
                    (a[i1][j1] * a[i2][j2] - a[i1][j2] * a[i2][j1]) / det
                })
            }))
        }

        pub fn propagate(a: &M3, p: &M3, b: &M3, r: &M3) -> M3 {
            add(&mul(&mul(a, p), &transpose(a)), &mul(&mul(b, r), &transpose(b)))
        }

        pub fn update(cov: &M3, si: &M3, y: &[f64; 3], r: &M3) -> ([f64; 3], M3) {
            let k = mul(cov, si);
            let dx = std::array::from_fn(|i| (0..3).map(|j| k[i][j] * y[j]).sum());
            let mut ik = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
            for i in 0..3 {
                for j in 0..3 {
                    ik[i][j] -= k[i][j];
                }
            }
            (dx, propagate(&ik, cov, &k, r))
        }

        pub fn nis(y: &[f64; 3], si: &M3) -> f64 {
            (0..3).map(|i| (0..3).map(|j| y[i] * si[i][j] * y[j]).sum::<f64>()).sum()
        }
    }

    /// Random numbers over many magnitudes, with exact zeros of both signs now and then.
    fn value(rng: &mut Rng) -> f64 {
        match rng.below(10) {
            0 => 0.0,
            1 => -0.0,
            _ => rng.normal() * 10f64.powf(rng.uniform() * 8.0 - 6.0),
        }
    }

    /// A random matrix: general, or covariance-like (symmetric positive semi-definite, often diagonal).
    fn matrix(rng: &mut Rng) -> reference::M3 {
        let a: reference::M3 = std::array::from_fn(|_| std::array::from_fn(|_| value(rng)));
        match rng.below(3) {
            0 => a,
            1 => reference::mul(&a, &reference::transpose(&a)),
            _ => [[a[0][0].abs(), 0.0, 0.0], [0.0, a[1][1].abs(), 0.0], [0.0, 0.0, a[2][2].abs()]],
        }
    }

    fn na(a: &reference::M3) -> Matrix3<f64> {
        Matrix3::from_fn(|i, j| a[i][j])
    }

    #[track_caller]
    fn assert_bits(new: &Matrix3<f64>, old: &reference::M3) {
        for i in 0..3 {
            for j in 0..3 {
                assert_eq!(new[(i, j)].to_bits(), old[i][j].to_bits(), "entry ({i}, {j}): {new} vs {old:?}");
            }
        }
    }

    #[test]
    fn nalgebra_reproduces_the_hand_written_algebra_bit_for_bit() {
        let mut rng = Rng::new(42);
        for _ in 0..20_000 {
            let [a, p, b, r, cov, si] = std::array::from_fn(|_| matrix(&mut rng));
            let y = std::array::from_fn(|_| value(&mut rng));
            let yv = Vector3::from(y);
            assert_bits(&propagate(&na(&a), &na(&p), &na(&b), &na(&r)), &reference::propagate(&a, &p, &b, &r));
            let (dx, c) = update(&na(&cov), &na(&si), &yv, &na(&r));
            let (dx_ref, c_ref) = reference::update(&cov, &si, &y, &r);
            assert_bits(&c, &c_ref);
            assert_eq!(dx.map(f64::to_bits), Vector3::from(dx_ref.map(f64::to_bits)));
            assert_eq!(nis(&yv, &na(&si)).to_bits(), reference::nis(&y, &si).to_bits());
            match (inverse(&na(&cov)), reference::inverse(&cov)) {
                (Some(i), Some(i_ref)) => assert_bits(&i, &i_ref),
                (None, None) => {}
                (i, i_ref) => panic!("{cov:?}: {i:?} vs {i_ref:?}"),
            }
            let f = value(&mut rng);
            let mut inflated = na(&cov);
            inflated *= f;
            assert_bits(&inflated, &cov.map(|row| row.map(|v| v * f)));
            assert_bits(&(na(&cov) + na(&r)), &reference::add(&cov, &r));
        }
    }

    #[test]
    fn update_pulls_towards_a_confident_match() {
        let mut l = Localizer::new(&NavConfig::default());
        l.predict(&Pose2::new(1.0, 0.0, 0.0));
        let m = Match { pose: Pose2::new(1.1, 0.05, 0.0), cov: diag(1e-4, 1e-4, 1e-5), inliers: 1.0 };
        assert!(l.correct(&m));
        assert!((l.pose().x - 1.1).abs() < 0.02 && (l.pose().y - 0.05).abs() < 0.02);
    }
}
