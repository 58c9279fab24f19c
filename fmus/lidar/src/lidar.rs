//! The `Lidar` model: keeps the base's recent path, and at every frame instant (on simulation
//! time) casts the frame's rays at the scene and publishes the cloud.
//!
//! Time: the frame published at T holds the pattern's points of [T - 1/frame_rate, T). By
//! default each is cast from the base pose at its own time (interpolated between the chassis
//! inputs, see [`crate::trajectory`]) and expressed in lidar_link at that time, as a real
//! sensor delivers them; header.stamp is the first point's time and `t` >= 0 the offset from
//! it, so a consumer can deskew. With `deskewed` every point is cast from the pose at the
//! frame's end instead (the latest input pose: the chassis pose at T itself is not known yet
//! during the step) and header.stamp is T, so `t` <= 0: a motion-compensated cloud for
//! consumers that do not deskew.

use crate::cloud::{CloudBuilder, Point};
use crate::frame::{yaw_rotate, Mount};
use crate::pattern::{Firing, ScanPattern};
use crate::ports::*;
use crate::reflectivity;
use crate::scene::{RobotInBaseLink, Scene};
use crate::trajectory::Trajectory;
use agrisim_fmi::{Log, Model, OutPort, Store, Var};
use agrisim_math::{Pose2, Rng};
use agrisim_msgs::sensor_msgs::PointCloud2;
use agrisim_msgs::Message;
use agrisim_raycast::{RayCaster, RigidPose};
use agrisim_schedule::{on_threads, to_ns, Schedule};
use agrisim_sensor_ports::MovedInput;
use agrisim_sky::environment::Environment;
use agrisim_sky::weather::Conditions;
use std::sync::Arc;

/// Most rays in one frame (memory and time guard; the port table bounds the cloud by it).
pub use crate::ports::MAX_POINTS_PER_FRAME;

/// Everything fixed at initialization.
#[derive(Clone, Debug)]
struct Config {
    scene: Arc<Scene>,
    pattern: ScanPattern,
    points_per_frame: usize,
    frame_period: f64,
    mount: Mount,
    range: (f64, f64),
    noise: f64,
    frame_id: String,
    deskewed: bool,
    drop_no_return: bool,
    /// Extinction coefficient of the air [1/m] (0 = clear).
    extinction: f64,
    visibility: f64,
    /// Threads casting a frame's rays.
    threads: usize,
}

/// What one captured frame produced.
pub struct Frame {
    pub cloud: PointCloud2,
    pub returns: usize,
}

#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct Lidar {
    /// Derived from the parameters: rebuilt, not serialized.
    #[serde(skip)]
    config: Option<Config>,
    trajectory: Trajectory,
    schedule: Schedule,
    rng: Rng,
    port: Option<OutPort>,
    window_ns: i64,
    /// The robot's body in base_link, re-posed from the inputs before each frame (derived
    /// from parameters and inputs: rebuilt, not serialized).
    #[serde(skip)]
    robot: Option<RobotInBaseLink>,
    /// The last frame's rays, cast into again (derived: not serialized).
    #[serde(skip)]
    rays: Vec<Ray>,
    /// Pushed leaves and picked fruit, from the world's `moved_objects`.
    moved: MovedInput,
    /// The moved objects where they are, for the frame (derived: rebuilt at each frame).
    #[serde(skip)]
    placed: Option<RayCaster>,
}

/// One point's ray: direction in lidar_link, time offset in the frame, echo.
#[derive(Clone, Copy, Debug, Default)]
struct Ray {
    sensor: [f64; 3],
    t: f32,
    /// What comes back: range and intensity (none: no hit, or too weak to detect).
    echo: Option<(f64, f32)>,
}

fn param(io: &Store, i: usize, ok: impl Fn(f64) -> bool, what: &str) -> Result<f64, String> {
    agrisim_fmi::checked_f64(io, VARIABLES, i, ok, what)
}

fn pose(io: &Store) -> Result<Pose2, String> {
    let (x, y, yaw) = SENSOR_PORTS.base_pose(io)?;
    Ok(Pose2 { x, y, yaw })
}

impl Config {
    fn from_params(io: &Store) -> Result<Config, String> {
        let positive = |v: f64| v > 0.0;
        let frame_rate = param(io, FRAME_RATE, positive, "positive")?;
        let point_rate = param(io, POINT_RATE, positive, "positive")?;
        let points_per_frame = (point_rate / frame_rate).round();
        if !(1.0..=MAX_POINTS_PER_FRAME as f64).contains(&points_per_frame) {
            return Err(format!(
                "point_rate / frame_rate = {points_per_frame} points per frame, outside [1, {MAX_POINTS_PER_FRAME}]"
            ));
        }
        let range_min = param(io, RANGE_MIN, |v| v >= 0.0, ">= 0")?;
        let range_max = param(io, RANGE_MAX, |v| v > range_min, "above range_min")?;
        let el_min = param(io, ELEVATION_MIN, |v| v.abs() < 90.0, "within (-90, 90) deg")?;
        let el_max =
            param(io, ELEVATION_MAX, |v| v.abs() < 90.0 && v > el_min, "within (-90, 90) deg and above elevation_min")?;
        let m = SENSOR_PORTS.mount(io)?;
        let mount = Mount::new(m.translation, m.roll, m.pitch, m.yaw);
        let (extinction, visibility) = match io.string(ENVIRONMENT).trim() {
            "" => (0.0, 0.0),
            text => {
                let env = Environment::from_toml_str(text).map_err(|e| format!("parameter environment: {e}"))?;
                let c = Conditions::of(&env);
                (c.extinction, c.visibility)
            }
        };
        let scene = SENSOR_PORTS.scene(io)?;
        let threads = match io.i32(CAST_THREADS) {
            t @ 1..=64 => t as usize,
            t => return Err(format!("parameter cast_threads must be in [1, 64], got {t}")),
        };
        Ok(Config {
            threads,
            scene,
            pattern: ScanPattern::mid360(point_rate, el_min.to_radians(), el_max.to_radians()),
            points_per_frame: points_per_frame as usize,
            frame_period: 1.0 / frame_rate,
            mount,
            range: (range_min, range_max),
            noise: param(io, RANGE_NOISE, |v| v >= 0.0, ">= 0")?,
            frame_id: io.string(FRAME_ID).to_string(),
            deskewed: io.bool(DESKEWED),
            drop_no_return: io.bool(DROP_NO_RETURN),
            extinction,
            visibility,
        })
    }
}

/// The detection test in attenuating air. The datasheet range `range_max` is where the
/// reference target's echo (10 % reflectivity, normal incidence) meets the detection
/// threshold in clear air; the echo falls as 1 / r^2 (extended Lambertian target) and as
/// exp(-2 beta r) through fog, rain or haze (there and back, Koschmieder's beta), so a return
/// at range r is detected while exp(-2 beta r) (range_max / r)^2 >= 1. Reflectivity and
/// incidence are not part of the test (as in clear air, where every hit within range_max
/// returns). beta = 0 leaves the clear-air behaviour exactly.
pub fn detected(r: f64, range_max: f64, beta: f64) -> bool {
    beta == 0.0 || (-2.0 * beta * r).exp() * (range_max / r).powi(2) >= 1.0
}

/// Points per ray packet (a few firings). 32: at the MID-360's density the rays of 64
/// consecutive points spread too far to share much of the tree (pattern rays, one thread:
/// 5.4-5.5e6 rays/s in packets of 32, 4.9e6 in packets of 64 or 48, 5.3e6 in 16).
pub const LIDAR_PACKET: usize = 32;
/// Points per run a thread casts at a time (whole packets: the packets are those of one
/// thread).
const RUN: usize = 16 * LIDAR_PACKET;

/// One packet's rays and results.
struct Batch {
    origins: [[f64; 3]; LIDAR_PACKET],
    dirs: [[f64; 3]; LIDAR_PACKET],
    poses: [RigidPose; LIDAR_PACKET],
    hits: [Option<agrisim_raycast::Hit>; LIDAR_PACKET],
}

impl Default for Batch {
    fn default() -> Batch {
        let pose = RigidPose::yawed(0.0, 0.0, 0.0, 0.0);
        Batch {
            origins: [[0.0; 3]; LIDAR_PACKET],
            dirs: [[0.0; 3]; LIDAR_PACKET],
            poses: [pose; LIDAR_PACKET],
            hits: [None; LIDAR_PACKET],
        }
    }
}

impl Lidar {
    /// Casts the frame that ends at `end_ns` (its points are the pattern's last
    /// `points_per_frame` before that instant).
    /// The robot's links are where the inputs last put them (set by [`Lidar::pose_robot`]
    /// before the frame; arms move little in one frame).
    pub fn capture(&mut self, end_ns: i64) -> Frame {
        let c = self.config.as_ref().expect("initialized");
        let p = &c.pattern;
        let n_end = (end_ns as f64 * 1e-9 * p.point_rate).floor() as i64;
        let n0 = n_end - c.points_per_frame as i64;
        let stamp_ns = if c.deskewed { end_ns } else { (p.time(n0) * 1e9).round() as i64 };
        // The rays, cast on the threads in runs of whole packets (each thread takes the next
        // run when done with one, so a thread the system holds back does not hold up the
        // frame) with what each one's return would be, then the points in order (the range
        // noise is drawn in point order, so the cloud does not depend on the threads). Every
        // ray is written anew: the buffer is only sized, not cleared.
        let mut rays = std::mem::take(&mut self.rays);
        rays.resize(c.points_per_frame, Ray::default());
        let this = &*self;
        on_threads(c.threads, rays.chunks_mut(RUN), |j, part| {
            this.cast_run(n0 + (j * RUN) as i64, end_ns, stamp_ns, part);
            0
        });
        let mut cloud = CloudBuilder::with_capacity(c.points_per_frame);
        let mut returns = 0;
        for ray in &rays {
            let (d_sensor, t) = (ray.sensor, ray.t);
            match ray.echo {
                Some((distance, intensity)) => {
                    let r = distance + self.rng.gauss(c.noise);
                    let xyz = [(d_sensor[0] * r) as f32, (d_sensor[1] * r) as f32, (d_sensor[2] * r) as f32];
                    cloud.push(&Point { xyz, intensity, t });
                    returns += 1;
                }
                None if c.drop_no_return => {}
                None => cloud.push(&Point { t, ..Point::default() }),
            }
        }
        self.rays = rays;
        Frame { cloud: cloud.finish(stamp_ns, &c.frame_id), returns }
    }

    /// Casts the rays of points `n0 ..` into `out` (one per point) in packets of consecutive
    /// points (successive firings look close together); each ray's hit is exactly its
    /// single-ray hit. Each ray's echo is what the hit returns, if strong enough to detect.
    fn cast_run(&self, n0: i64, end_ns: i64, stamp_ns: i64, out: &mut [Ray]) {
        let c = self.config.as_ref().expect("initialized");
        let robot = &self.robot.as_ref().expect("initialized").caster;
        let empty = RayCaster::new(&[]);
        let placed = self.placed.as_ref().unwrap_or(&empty);
        let scene = self.moved.scene(&c.scene);
        let p = &c.pattern;
        let end_pose = self.trajectory.at(end_ns as f64 * 1e-9);
        let stamp_s = stamp_ns as f64 * 1e-9;
        // What the beams of one firing share: its time, pattern state and base pose.
        let mut firing: Option<(i64, Firing, RigidPose)> = None;
        let beams = p.beams as i64;
        let mut batch = Batch::default();
        for (k0, rays) in out.chunks_mut(LIDAR_PACKET).enumerate() {
            for (i, ray) in rays.iter_mut().enumerate() {
                let n = n0 + (k0 * LIDAR_PACKET + i) as i64;
                let f = n.div_euclid(beams);
                let (fs, base) = match firing {
                    Some((g, fs, base)) if g == f => (fs, base),
                    _ => {
                        let fs = p.firing(f);
                        let pose = if c.deskewed { end_pose } else { self.trajectory.at(fs.time) };
                        let base = RigidPose::yawed(pose.x, pose.y, 0.0, pose.yaw);
                        firing = Some((f, fs, base));
                        (fs, base)
                    }
                };
                let (sin, cos) = (base.rotation[1][0], base.rotation[0][0]);
                let d_sensor = p.beam_direction(&fs, p.beam(n));
                let m = yaw_rotate(sin, cos, c.mount.translation);
                ray.sensor = d_sensor;
                ray.t = (fs.time - stamp_s) as f32;
                batch.dirs[i] = yaw_rotate(sin, cos, c.mount.rotate(d_sensor));
                batch.origins[i] = [base.translation[0] + m[0], base.translation[1] + m[1], m[2]];
                batch.poses[i] = base;
            }
            let k = rays.len();
            scene.caster.cast_packet_posed(
                &batch.origins[..k],
                &batch.dirs[..k],
                c.range.0,
                c.range.1,
                placed,
                robot,
                &batch.poses[..k],
                &mut batch.hits[..k],
            );
            for ((ray, hit), d) in rays.iter_mut().zip(&batch.hits[..k]).zip(&batch.dirs[..k]) {
                ray.echo = hit.filter(|h| detected(h.distance, c.range.1, c.extinction)).map(|h| {
                    let rho = reflectivity::of_kind(c.scene.kind(h.object));
                    let cos_incidence = -(h.normal[0] * d[0] + h.normal[1] * d[1] + h.normal[2] * d[2]);
                    (h.distance, reflectivity::intensity(rho, cos_incidence))
                });
            }
        }
    }

    /// Poses the robot's links for `coords` (None: the base box only).
    pub fn pose_robot(&mut self, coords: Option<agrisim_sensor_ports::robot::Coords>) {
        if let Some(r) = self.robot.as_mut() {
            r.update(coords);
        }
    }

    /// The scene the rays are cast at (after initialization).
    pub fn scene(&self) -> Option<&Scene> {
        self.config.as_ref().map(|c| &*c.scene)
    }
}

impl Model for Lidar {
    const NAME: &'static str = "Lidar";
    const DESCRIPTION: &'static str = "LiDAR modelled on the Livox MID-360 (non-repetitive pattern, 200k points/s, 10 Hz frames) cast at the greenhouse scene: sensor_msgs/PointCloud2";
    const VARIABLES: &'static [Var] = VARIABLES;

    fn save_state(&self, out: &mut Vec<u8>) -> Result<(), agrisim_fmi::ModelError> {
        agrisim_fmi::serial::write(self, out)
    }

    fn load_state(&mut self, bytes: &[u8]) -> Result<(), agrisim_fmi::ModelError> {
        agrisim_fmi::serial::load_keeping(self, bytes, |new, old| {
            new.config = old.config.take();
            new.robot = old.robot.take();
        })
    }

    fn new() -> Self {
        Self::default()
    }

    fn initialize(&mut self, io: &mut Store, start_time: f64, _log: &mut dyn Log) -> Result<(), String> {
        let config = Config::from_params(io)?;
        self.trajectory = Trajectory::default();
        self.trajectory.push(start_time, pose(io)?, 2.0 * config.frame_period);
        self.schedule = Schedule::new(1.0 / config.frame_period, start_time)?;
        // No frame at the start instant: it would cover time before the run.
        self.schedule.due(start_time);
        self.rng = Rng::new(io.i32(NOISE_SEED) as u32 as u64);
        self.window_ns = agrisim_fmi::port::window_ns(io, PORT_WINDOW)?;
        self.port = Some(OutPort::new(POINTS, POINTS_SEQ));
        self.port.as_mut().expect("set above").sync(io, to_ns(start_time), self.window_ns);
        io.set_f64(VISIBILITY, config.visibility);
        let body = SENSOR_PORTS.robot_body(io, config.scene.object_count() as u32)?;
        self.robot = Some(RobotInBaseLink::new(body, SENSOR_PORTS.coords(io)?));
        self.moved = MovedInput::new(&SENSOR_PORTS);
        self.placed = None;
        self.config = Some(config);
        Ok(())
    }

    fn do_step(&mut self, io: &mut Store, t: f64, h: f64, _log: &mut dyn Log) -> Result<(), String> {
        let period = self.config.as_ref().map_or(0.1, |c| c.frame_period);
        self.trajectory.push(t, pose(io)?, 2.0 * period + h);
        let c = self.config.as_ref().ok_or("not initialized")?;
        self.moved.take(io, &SENSOR_PORTS, &c.scene)?;
        if let Some(end_ns) = self.schedule.due(t + h) {
            self.pose_robot(SENSOR_PORTS.coords(io)?);
            let moved = self.moved.objects();
            self.placed = (!moved.is_empty()).then(|| RayCaster::new(&moved));
            let frame = self.capture(end_ns);
            io.set_i32(POINTS_IN_FRAME, frame.cloud.width as i32);
            io.set_i32(RETURNS_IN_FRAME, frame.returns as i32);
            let port = self.port.as_mut().ok_or("not initialized")?;
            port.publish(frame.cloud.header.stamp.to_nanos(), frame.cloud.to_cdr());
        }
        if let Some(port) = self.port.as_mut() {
            port.sync(io, to_ns(t + h), self.window_ns);
        }
        Ok(())
    }
}
