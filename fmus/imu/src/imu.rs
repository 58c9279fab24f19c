//! The `Imu` model: chassis ground truth in, samples at the configured rate on simulation
//! time out; the message port carries every sample (the scalar outputs the latest one).

use crate::frame::Quat;
use crate::motion::{BaseState, HeldMotion, Mount};
use crate::noise::NoiseParams;
use crate::ports::*;
use crate::sensor::{ImuSensor, Sample};
use agrisim_fmi::{Log, Model, OutPort, Store, Var};
use agrisim_msgs::builtin_interfaces::Time;
use agrisim_msgs::geometry_msgs::{Quaternion, Vector3};
use agrisim_msgs::sensor_msgs;
use agrisim_msgs::std_msgs::Header;
use agrisim_msgs::Message;
use agrisim_schedule::to_ns;

#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct Imu {
    sensor: ImuSensor,
    motion: HeldMotion,
    frame_id: String,
    orientation_enabled: bool,
    port: Option<OutPort>,
    window_ns: i64,
    /// End of the last step [ns]: samples of the next step come after it.
    now_ns: i64,
}

fn finite(io: &Store, i: usize) -> Result<f64, String> {
    let v = io.f64(i);
    if v.is_finite() {
        Ok(v)
    } else {
        Err(format!("parameter {} must be finite, got {v}", VARIABLES[i].name))
    }
}

/// Gyro or accelerometer noise parameters from six consecutive table rows.
fn noise_params(io: &Store, first: usize) -> NoiseParams {
    NoiseParams {
        noise_density: io.f64(first),
        bias_mean: io.f64(first + 1),
        bias_stddev: io.f64(first + 2),
        dynamic_bias_stddev: io.f64(first + 3),
        dynamic_bias_correlation_time: io.f64(first + 4),
        bias_instability: io.f64(first + 5),
    }
}

/// The gyro noise parameters in `io` (defaults unless changed), for tests and tools.
pub fn gyro_params(io: &Store) -> NoiseParams {
    noise_params(io, GYRO_NOISE_DENSITY)
}

/// The accelerometer noise parameters in `io`.
pub fn accel_params(io: &Store) -> NoiseParams {
    noise_params(io, ACCEL_NOISE_DENSITY)
}

/// The mount pose in `io`.
pub fn mount(io: &Store) -> Result<Mount, String> {
    let [x, y, z, roll, pitch, yaw] =
        [MOUNT_X, MOUNT_Y, MOUNT_Z, MOUNT_ROLL, MOUNT_PITCH, MOUNT_YAW].map(|i| finite(io, i));
    Ok(Mount { translation: [x?, y?, z?], rotation: Quat::from_rpy(roll?, pitch?, yaw?) })
}

/// An [`ImuSensor`] configured from the parameters in `io`, its noise starting at `start_ns`.
pub fn sensor_from(io: &Store, start_ns: i64) -> Result<ImuSensor, String> {
    let gravity = finite(io, GRAVITY)?;
    let seed = io.i32(SEED) as u32 as u64;
    ImuSensor::new(io.f64(RATE), mount(io)?, gravity, &gyro_params(io), &accel_params(io), seed, start_ns)
}

fn base_state(io: &Store) -> BaseState {
    BaseState { yaw: io.f64(BASE_YAW), vx: io.f64(VX), vy: io.f64(VY), wz: io.f64(WZ) }
}

fn vector(v: [f64; 3]) -> Vector3 {
    Vector3 { x: v[0], y: v[1], z: v[2] }
}

fn diagonal(variance: f64) -> [f64; 9] {
    let mut c = [0.0; 9];
    c[0] = variance;
    c[4] = variance;
    c[8] = variance;
    c
}

impl Imu {
    /// The sample as sensor_msgs/Imu. Covariances: the per-sample white noise (biases are
    /// not in them, as for a real driver); orientation is ground truth, or absent (-1).
    pub fn message(&self, s: &Sample) -> sensor_msgs::Imu {
        let (gw, aw) = self.sensor.white_stddev();
        let (orientation, mut orientation_covariance) = if self.orientation_enabled {
            let q = s.orientation;
            (Quaternion { x: q.x, y: q.y, z: q.z, w: q.w }, [0.0; 9])
        } else {
            (Quaternion::IDENTITY, [0.0; 9])
        };
        if !self.orientation_enabled {
            orientation_covariance[0] = -1.0;
        }
        sensor_msgs::Imu {
            header: Header::new(Time::from_nanos(s.stamp_ns), self.frame_id.clone()),
            orientation,
            orientation_covariance,
            angular_velocity: vector(s.angular_velocity),
            angular_velocity_covariance: diagonal(gw * gw),
            linear_acceleration: vector(s.linear_acceleration),
            linear_acceleration_covariance: diagonal(aw * aw),
        }
    }

    fn publish(&mut self, io: &mut Store, s: &Sample) {
        for i in 0..3 {
            io.set_f64(GYRO[i], s.angular_velocity[i]);
            io.set_f64(ACCEL[i], s.linear_acceleration[i]);
        }
        let cdr = self.message(s).to_cdr();
        self.port.get_or_insert_with(|| OutPort::new(IMU, IMU_SEQ)).publish(s.stamp_ns, cdr);
    }

    fn sync(&mut self, io: &mut Store) {
        self.port.get_or_insert_with(|| OutPort::new(IMU, IMU_SEQ)).sync(io, self.now_ns, self.window_ns);
    }
}

impl Model for Imu {
    const NAME: &'static str = "Imu";
    const DESCRIPTION: &'static str = "IMU on the mobile base (ICM-40609-D noise figures, gz-sensors noise model): sensor_msgs/Imu at a configurable rate";
    const VARIABLES: &'static [Var] = VARIABLES;

    agrisim_fmi::whole_state!();

    fn new() -> Self {
        Self::default()
    }

    fn initialize(&mut self, io: &mut Store, start_time: f64, _log: &mut dyn Log) -> Result<(), String> {
        let start_ns = to_ns(start_time);
        self.sensor = sensor_from(io, start_ns)?;
        self.frame_id = io.string(FRAME_ID).to_string();
        self.orientation_enabled = io.bool(ENABLE_ORIENTATION);
        self.motion = HeldMotion::start(start_time, base_state(io));
        self.port = None;
        self.window_ns = agrisim_fmi::port::window_ns(io, PORT_WINDOW)?;
        self.now_ns = start_ns;
        let truth = self.motion.truth_at(start_time, &self.sensor.mount, self.sensor.gravity);
        let s = self.sensor.sample(start_ns, &truth);
        self.publish(io, &s);
        self.sync(io);
        Ok(())
    }

    fn do_step(&mut self, io: &mut Store, t: f64, h: f64, _log: &mut dyn Log) -> Result<(), String> {
        self.motion.update(t, base_state(io));
        let end_ns = to_ns(t + h);
        for stamp in self.sensor.instants(self.now_ns, end_ns) {
            let truth = self.motion.truth_at(stamp as f64 * 1e-9, &self.sensor.mount, self.sensor.gravity);
            let s = self.sensor.sample(stamp, &truth);
            self.publish(io, &s);
        }
        self.now_ns = end_ns;
        self.sync(io);
        Ok(())
    }
}
