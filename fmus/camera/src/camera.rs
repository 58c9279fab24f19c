//! The `Camera` model: at every frame instant (k / frame_rate on simulation time) renders the
//! scene from the latest base pose and robot inputs and publishes colour, depth, CameraInfo and
//! labels; at its first step it publishes its own frames for TF.
//!
//! The frame due at T is rendered during the step that reaches T, from the pose at the step's
//! start (the chassis pose at T is not known yet): up to one communication step of lag
//! (2 cm at 1 m/s with the 0.02 s step). Global shutter; colour and depth are co-registered
//! (as the driver's aligned depth), one optical frame.
//!
//! Where the camera is: camera_link at the mount pose in the frame of the URDF link
//! `mount_parent` (base_link, the lift carriage, a wrist...), which the robot's forward
//! kinematics (`agrisim_robot::model`, the world's and the LiDAR's) place from the lift and arm
//! inputs; the optical frame is camera_link turned to z forward, x right, y down. The same
//! chain is what TF gives: robot_state_publisher's base_link -> mount_parent, then this
//! camera's `tf_static` (mount_parent -> link_frame -> frame_id).

use crate::image;
use crate::lighting::Lighting;
use crate::optics::{CameraPose, Intrinsics, Mount, OPTICAL_IN_BODY};
use crate::ports::*;
use crate::render::{self, DepthModel, DepthNoise, Frame, Shot};
use crate::scene::Scene;
use agrisim_fmi::{Log, Model, OutPort, Store, Var};
use agrisim_math::Rng;
use agrisim_msgs::builtin_interfaces::Time;
use agrisim_msgs::geometry_msgs::{Quaternion, Transform, TransformStamped, Vector3};
use agrisim_msgs::std_msgs::Header;
use agrisim_msgs::tf2_msgs::TFMessage;
use agrisim_msgs::Message;
use agrisim_raycast::SunColumns;
use agrisim_robot::model::RobotModel;
use agrisim_robot::Pose as RPose;
use agrisim_schedule::{to_ns, Schedule};
use agrisim_sensor_ports::robot::{self as robot_ports, Coords, RobotBody};
use agrisim_sensor_ports::MovedInput;
use agrisim_sky::environment::Environment;
use agrisim_sky::weather::Conditions;
use std::sync::Arc;

pub use crate::ports::MAX_SIDE;

/// The optical frame in camera_link (a pure rotation).
const OPTICAL: RPose = RPose { rot: OPTICAL_IN_BODY, trans: [0.0; 3] };

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
    /// TF name of camera_link (the body frame the mount places).
    pub link_frame: String,
    /// The link the camera rides on: its name and index in `model`'s links.
    pub parent: (String, usize),
    /// camera_link in the parent link's frame (`mount` as a transform).
    pub mount_pose: RPose,
    /// The robot's kinematics (the URDF), which place the parent link.
    pub model: Arc<RobotModel>,
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
    /// image, depth, camera_info, labels, tf_static.
    ports: Option<[OutPort; 5]>,
    /// The camera's frames went out on tf_static (at the first step).
    tf_sent: bool,
    /// Pushed leaves and picked fruit, from the world's `moved_objects`.
    moved: MovedInput,
    window_ns: i64,
    /// The last frame's buffers, rendered into again (derived: not serialized).
    #[serde(skip)]
    frame: Frame,
}

fn new_ports() -> [OutPort; 5] {
    [
        OutPort::new(IMAGE, IMAGE_SEQ),
        OutPort::new(DEPTH, DEPTH_SEQ),
        OutPort::new(CAMERA_INFO, CAMERA_INFO_SEQ),
        OutPort::new(LABELS_IMAGE, LABELS_SEQ),
        OutPort::new(TF_STATIC, TF_STATIC_SEQ),
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
        let model = robot_ports::model()?;
        let parent_name = io.string(MOUNT_PARENT).trim().to_string();
        let parent = model.link_index(&parent_name).ok_or_else(|| {
            format!(
                "parameter mount_parent = {parent_name:?} is not a link of the robot (agrisim_robot.urdf); its links: {}",
                model.link_names.join(", ")
            )
        })?;
        let link_frame = frame_name(io, LINK_FRAME)?;
        let frame_id = frame_name(io, FRAME_ID)?;
        if link_frame == frame_id || link_frame == parent_name || frame_id == parent_name {
            return Err(format!(
                "parameters mount_parent, link_frame and frame_id must name three different frames, got {parent_name:?}, {link_frame:?}, {frame_id:?}"
            ));
        }
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
        // The camera's own housing, if the URDF has it (the default camera's camera_link), is
        // left out: the rays start inside it. Any other camera sees it.
        let robot = RobotBody::new(scene.object_count() as u32, SENSOR_PORTS.base_box(io)?, &link_frame)?;
        Ok(Config {
            robot,
            robot_links: io.bool(ROBOT_LINKS),
            mount_pose: RPose::from_xyz_rpy(mount.translation, [mount.roll, mount.pitch, mount.yaw]),
            parent: (parent_name, parent),
            model,
            link_frame,
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
            frame_id,
        })
    }

    /// The optical frame in base_link with the robot at `coords` (the URDF's forward
    /// kinematics to the parent link, then the mount, then the optical axes).
    pub fn optical_in_base(&self, coords: &Coords) -> RPose {
        let mut fk = Vec::new();
        self.model.fk(coords, &mut fk);
        fk[self.parent.1].mul(&self.mount_pose).mul(&OPTICAL)
    }

    /// The optical frame in the map with base_link at (x, y, yaw) and the robot at `coords`.
    pub fn camera_pose(&self, coords: &Coords, x: f64, y: f64, yaw: f64) -> CameraPose {
        let p = RPose::from_xyz_rpy([x, y, 0.0], [0.0, 0.0, yaw]).mul(&self.optical_in_base(coords));
        CameraPose { origin: p.trans, rotation: p.rot }
    }

    /// The camera's fixed frames stamped `stamp_ns`: parent -> link_frame (the mount) and
    /// link_frame -> frame_id (the optical axes), as a static TF broadcaster sends them.
    pub fn tf_static(&self, stamp_ns: i64) -> TFMessage {
        TFMessage {
            transforms: vec![
                stamped(stamp_ns, &self.parent.0, &self.link_frame, &self.mount_pose),
                stamped(stamp_ns, &self.link_frame, &self.frame_id, &OPTICAL),
            ],
        }
    }
}

/// A TF frame name parameter: non-empty, no blanks, no leading '/' (tf2 refuses those).
fn frame_name(io: &Store, i: usize) -> Result<String, String> {
    let v = io.string(i);
    if v.is_empty() || v.starts_with('/') || v.chars().any(char::is_whitespace) {
        return Err(format!(
            "parameter {} = {v:?} is not a TF frame name (non-empty, no blanks, no leading '/')",
            VARIABLES[i].name
        ));
    }
    Ok(v.to_string())
}

fn stamped(stamp_ns: i64, parent: &str, child: &str, p: &RPose) -> TransformStamped {
    let [x, y, z, w] = p.quaternion();
    TransformStamped {
        header: Header::new(Time::from_nanos(stamp_ns), parent),
        child_frame_id: child.to_string(),
        transform: Transform {
            translation: Vector3 { x: p.trans[0], y: p.trans[1], z: p.trans[2] },
            rotation: Quaternion { x, y, z, w },
        },
    }
}

/// The lift and arm inputs, which place the camera whether or not it sees the links
/// (finite, below 1e3, as the shared readers require).
fn placement(io: &Store) -> Result<Coords, String> {
    let get = |i: usize| {
        let v = io.f64(i);
        if v.is_finite() && v.abs() < 1e3 {
            Ok(v)
        } else {
            Err(format!("input {} = {v} is not finite or beyond 1e3", VARIABLES[i].name))
        }
    };
    let p = &SENSOR_PORTS;
    let mut c = Coords { lift: get(p.lift)?, ..Coords::default() };
    for side in 0..2 {
        for (q, &i) in c.arms[side].iter_mut().zip(&p.arms[side]) {
            *q = get(i)?;
        }
        c.widths[side] = get(p.widths[side])?;
    }
    Ok(c)
}

impl Camera {
    /// Renders a frame with base_link at (x, y, yaw) (advances the noise generator), the robot
    /// in its default configuration (lift down, arms in the ready pose).
    pub fn capture(&mut self, x: f64, y: f64, yaw: f64) -> Frame {
        self.capture_at(x, y, yaw, &Coords::default())
    }

    /// A frame with base_link at (x, y, yaw) and the robot at `coords`: they place the camera
    /// (on its parent link) and, with `robot_links`, the links it sees.
    pub fn capture_at(&mut self, x: f64, y: f64, yaw: f64, coords: &Coords) -> Frame {
        let mut frame = Frame::default();
        self.render_posed(&mut frame, x, y, yaw, coords);
        frame
    }

    /// [`Camera::capture_at`] into `frame`'s buffers.
    fn render_posed(&mut self, frame: &mut Frame, x: f64, y: f64, yaw: f64, coords: &Coords) {
        let c = self.config.as_ref().expect("initialized");
        let mut dynamic = c.robot.objects(c.robot_links.then_some(coords), x, y, yaw);
        dynamic.extend(self.moved.objects());
        let pose = c.camera_pose(coords, x, y, yaw);
        let shot = Shot {
            scene: self.moved.scene(&c.scene),
            dynamic: &dynamic,
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
        self.tf_sent = false;
        self.moved = MovedInput::new(&SENSOR_PORTS);
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
        let coords = placement(io)?;
        let c = self.config.as_ref().ok_or("not initialized")?;
        self.moved.take(io, &SENSOR_PORTS, &c.scene)?;
        if !self.tf_sent {
            let stamp = to_ns(t);
            let tf = c.tf_static(stamp).to_cdr();
            self.ports.get_or_insert_with(new_ports)[4].publish(stamp, tf);
            self.tf_sent = true;
        }
        if let Some(stamp) = self.schedule.due(t + h) {
            self.capture_and_publish(io, stamp, x, y, yaw, &coords);
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

    fn capture_and_publish(&mut self, io: &mut Store, stamp: i64, x: f64, y: f64, yaw: f64, coords: &Coords) {
        let mut frame = std::mem::take(&mut self.frame);
        self.render_posed(&mut frame, x, y, yaw, coords);
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
