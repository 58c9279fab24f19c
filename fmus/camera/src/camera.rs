//! The `Camera` model: at every frame instant (k / frame_rate on simulation time) renders the
//! scene from the latest base pose input and publishes colour, depth, CameraInfo and labels.
//!
//! The frame due at T is rendered during the step that reaches T, from the pose at the step's
//! start (the chassis pose at T is not known yet): up to one communication step of lag
//! (2 cm at 1 m/s with the 0.02 s step). Global shutter; colour and depth are co-registered
//! (as the driver's aligned depth), one optical frame.

use crate::image;
use crate::lighting::Lighting;
use crate::optics::{CameraPose, Intrinsics, Mount};
use crate::ports::*;
use crate::render::{self, DepthModel, DepthNoise, Frame, Shot};
use crate::scene::Scene;
use agrisim_fmi::{Log, Model, OutPort, Store, Var};
use agrisim_math::Rng;
use agrisim_msgs::Message;
use agrisim_raycast::SunColumns;
use agrisim_schedule::{to_ns, Schedule};
use agrisim_sensor_ports::robot::{Coords, RobotBody};
use agrisim_sky::environment::Environment;
use agrisim_sky::weather::Conditions;
use std::sync::Arc;

pub use crate::ports::MAX_SIDE;

#[derive(Clone, Debug)]
pub struct Config {
    pub scene: Arc<Scene>,
    pub intrinsics: Intrinsics,
    pub period: f64,
    pub mount: Mount,
    pub depth: DepthModel,
    pub light: Lighting,
    /// Per sun sample of `light`, which shadow rays no opaque object can stop
    /// ([`render::sun_columns`]; empty without shadows).
    pub columns: Arc<Vec<SunColumns>>,
    pub labels: bool,
    /// Sun, weather and visibility from the `environment` parameter (None = fixed sun).
    pub conditions: Option<Conditions>,
    pub threads: usize,
    pub frame_id: String,
    /// The robot's own body (base box and, with `robot_links`, its URDF links).
    pub robot: RobotBody,
    pub robot_links: bool,
}

#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct Camera {
    /// Derived from the parameters: rebuilt, not serialized.
    #[serde(skip)]
    config: Option<Config>,
    schedule: Schedule,
    rng: Rng,
    /// image, depth, camera_info, labels.
    ports: Option<[OutPort; 4]>,
    window_ns: i64,
    /// The last frame's buffers, rendered into again (derived: not serialized).
    #[serde(skip)]
    frame: Frame,
}

fn new_ports() -> [OutPort; 4] {
    [
        OutPort::new(IMAGE, IMAGE_SEQ),
        OutPort::new(DEPTH, DEPTH_SEQ),
        OutPort::new(CAMERA_INFO, CAMERA_INFO_SEQ),
        OutPort::new(LABELS_IMAGE, LABELS_SEQ),
    ]
}

fn param(io: &Store, i: usize, ok: impl Fn(f64) -> bool, what: &str) -> Result<f64, String> {
    agrisim_fmi::checked_f64(io, VARIABLES, i, ok, what)
}

fn side(io: &Store, i: usize) -> Result<u32, String> {
    let v = io.i32(i);
    if (1..=MAX_SIDE).contains(&v) {
        Ok(v as u32)
    } else {
        Err(format!("parameter {} must be in [1, {MAX_SIDE}], got {v}", VARIABLES[i].name))
    }
}

impl Config {
    pub fn from_params(io: &Store) -> Result<Config, String> {
        let any = |_: f64| true;
        let fov = |v: f64| v > 0.0 && v < 180.0;
        let width = side(io, WIDTH)?;
        let height = side(io, HEIGHT)?;
        let fov_v = param(io, FOV_V, fov, "in (0, 180) deg")?;
        let fov_h = match param(io, FOV_H, |v| v == 0.0 || fov(v), "0 (square pixels) or in (0, 180) deg")? {
            0.0 => 2.0 * (width as f64 / height as f64 * (0.5 * fov_v.to_radians()).tan()).atan().to_degrees(),
            v => v,
        };
        let rate = param(io, FRAME_RATE, |v| v > 0.0 && v <= 1000.0, "in (0, 1000] Hz")?;
        let range_min = param(io, RANGE_MIN, |v| v >= 0.0, ">= 0")?;
        let range_max = param(io, RANGE_MAX, |v| v > range_min, "above range_min")?;
        let noise = match io.i32(DEPTH_NOISE_MODEL) {
            0 => DepthNoise::None,
            1 => DepthNoise::Fixed { sigma: param(io, DEPTH_NOISE_SIGMA, |v| v >= 0.0, ">= 0")? },
            2 => DepthNoise::Stereo { subpixel: param(io, SUBPIXEL, |v| v >= 0.0, ">= 0")? },
            m => return Err(format!("parameter depth_noise_model must be 0 (none), 1 (fixed) or 2 (stereo), got {m}")),
        };
        let mount = SENSOR_PORTS.mount(io)?;
        let conditions = match io.string(ENVIRONMENT).trim() {
            "" => None,
            text => Some(Conditions::of(
                &Environment::from_toml_str(text).map_err(|e| format!("parameter environment: {e}"))?,
            )),
        };
        let fixed = Lighting::new(
            param(io, SUN_AZIMUTH, any, "finite")?,
            param(io, SUN_ELEVATION, |v| v.abs() <= 90.0, "in [-90, 90] deg")?,
            param(io, AMBIENT, |v| v >= 0.0, ">= 0")?,
        );
        let light = conditions.as_ref().map_or(fixed, Lighting::from_conditions);
        let threads = match io.i32(RENDER_THREADS) {
            t @ 1..=64 => t as usize,
            t => return Err(format!("parameter render_threads must be in [1, 64], got {t}")),
        };
        let scene = SENSOR_PORTS.scene(io)?;
        let columns = Arc::new(render::sun_columns(&scene, &light));
        Ok(Config {
            robot: SENSOR_PORTS.robot_body(io, scene.object_count() as u32)?,
            robot_links: io.bool(ROBOT_LINKS),
            scene,
            intrinsics: Intrinsics::from_fov(width, height, fov_h, fov_v),
            period: 1.0 / rate,
            mount,
            depth: DepthModel {
                range: (range_min, range_max),
                noise,
                baseline: param(io, BASELINE, |v| v > 0.0, "positive")?,
                invalid_band: io.bool(INVALID_BAND),
                edge_ratio: param(io, EDGE_RATIO, |v| v >= 0.0, ">= 0")?,
            },
            light,
            columns,
            labels: io.bool(LABELS),
            conditions,
            threads,
            frame_id: io.string(FRAME_ID).to_string(),
        })
    }
}

impl Camera {
    /// Renders a frame with base_link at (x, y, yaw) (advances the noise generator); the
    /// arms, if seen, in their default (ready) pose.
    pub fn capture(&mut self, x: f64, y: f64, yaw: f64) -> Frame {
        self.capture_on_lift(x, y, yaw, 0.0)
    }

    /// As [`Camera::capture`] with the lift (and the camera on it) raised by `lift` metres.
    pub fn capture_on_lift(&mut self, x: f64, y: f64, yaw: f64, lift: f64) -> Frame {
        let links = self.config.as_ref().is_some_and(|c| c.robot_links);
        let coords = links.then(|| Coords { lift, ..Coords::default() });
        self.capture_posed(x, y, yaw, lift, coords.as_ref())
    }

    /// A frame with the camera raised by `lift` and the robot's links at `coords` (None: the
    /// base box only).
    pub fn capture_posed(&mut self, x: f64, y: f64, yaw: f64, lift: f64, coords: Option<&Coords>) -> Frame {
        let mut frame = Frame::default();
        self.render_posed(&mut frame, x, y, yaw, lift, coords);
        frame
    }

    /// [`Camera::capture_posed`] into `frame`'s buffers.
    fn render_posed(&mut self, frame: &mut Frame, x: f64, y: f64, yaw: f64, lift: f64, coords: Option<&Coords>) {
        let c = self.config.as_ref().expect("initialized");
        let robot = c.robot.objects(coords, x, y, yaw);
        let mut mount = c.mount;
        mount.translation[2] += lift;
        let pose = CameraPose::new(&mount, x, y, yaw);
        let shot = Shot {
            scene: &c.scene,
            dynamic: &robot,
            k: &c.intrinsics,
            pose: &pose,
            light: &c.light,
            columns: &c.columns,
            depth: &c.depth,
        };
        render::render_into(frame, &shot, &mut self.rng, c.threads);
    }

    pub fn config(&self) -> Option<&Config> {
        self.config.as_ref()
    }
}

impl Model for Camera {
    const NAME: &'static str = "Camera";
    const DESCRIPTION: &'static str = "RGB-D camera modelled on the Intel RealSense D435i (1280x720, 87x58 deg, 10 Hz): rgb8 + 32FC1 depth with stereo noise + CameraInfo + instance labels, ray cast at the greenhouse scene";
    const VARIABLES: &'static [Var] = VARIABLES;

    fn save_state(&self, out: &mut Vec<u8>) -> Result<(), agrisim_fmi::ModelError> {
        agrisim_fmi::serial::write(self, out)
    }

    fn load_state(&mut self, bytes: &[u8]) -> Result<(), agrisim_fmi::ModelError> {
        agrisim_fmi::serial::load_keeping(self, bytes, |new, old| new.config = old.config.take())
    }

    fn new() -> Self {
        Self::default()
    }

    fn initialize(&mut self, io: &mut Store, start_time: f64, _log: &mut dyn Log) -> Result<(), String> {
        let config = Config::from_params(io)?;
        SENSOR_PORTS.base_pose(io)?;
        self.schedule = Schedule::new(1.0 / config.period, start_time)?;
        self.rng = Rng::new(io.i32(NOISE_SEED) as u32 as u64);
        self.window_ns = agrisim_fmi::port::window_ns(io, PORT_WINDOW)?;
        self.ports = Some(new_ports());
        self.sync(io, to_ns(start_time));
        let (zenith, azimuth, visibility) = match &config.conditions {
            Some(c) => (c.sun.zenith, c.sun.azimuth, c.visibility),
            None => (90.0 - io.f64(SUN_ELEVATION), io.f64(SUN_AZIMUTH), 0.0),
        };
        io.set_f64(SOLAR_ZENITH, zenith);
        io.set_f64(SOLAR_AZIMUTH, azimuth);
        io.set_f64(VISIBILITY, visibility);
        self.config = Some(config);
        Ok(())
    }

    fn do_step(&mut self, io: &mut Store, t: f64, h: f64, _log: &mut dyn Log) -> Result<(), String> {
        let (x, y, yaw) = SENSOR_PORTS.base_pose(io)?;
        let lift = io.f64(LIFT_POSITION);
        if !(lift.is_finite() && lift.abs() < 100.0) {
            return Err(format!("input lift_position = {lift} is not finite or beyond 100 m"));
        }
        if let Some(stamp) = self.schedule.due(t + h) {
            let coords = SENSOR_PORTS.coords(io)?;
            self.capture_and_publish(io, stamp, x, y, yaw, lift, coords.as_ref());
        }
        self.sync(io, to_ns(t + h));
        Ok(())
    }
}

impl Camera {
    fn sync(&mut self, io: &mut Store, now_ns: i64) {
        let w = self.window_ns;
        for p in self.ports.get_or_insert_with(new_ports) {
            p.sync(io, now_ns, w);
        }
    }

    #[allow(clippy::too_many_arguments)]
    fn capture_and_publish(
        &mut self,
        io: &mut Store,
        stamp: i64,
        x: f64,
        y: f64,
        yaw: f64,
        lift: f64,
        coords: Option<&Coords>,
    ) {
        let mut frame = std::mem::take(&mut self.frame);
        self.render_posed(&mut frame, x, y, yaw, lift, coords);
        let c = self.config.as_ref().expect("initialized");
        let (w, hh, id) = (c.intrinsics.width, c.intrinsics.height, c.frame_id.as_str());
        let info = c.intrinsics.camera_info(stamp, id).to_cdr();
        let rgb = image::rgb8_cdr(stamp, id, w, hh, &frame.rgb);
        let depth = image::depth_32fc1_cdr(stamp, id, w, hh, &frame.depth);
        let labels = c.labels.then(|| image::labels_32sc1_cdr(stamp, id, w, hh, &frame.labels));
        let ports = self.ports.get_or_insert_with(new_ports);
        ports[0].publish(stamp, rgb);
        ports[1].publish(stamp, depth);
        ports[2].publish(stamp, info);
        if let Some(l) = labels {
            ports[3].publish(stamp, l);
        }
        io.set_i32(VALID_DEPTH, frame.valid as i32);
        self.frame = frame;
    }
}
