//! The model: dead reckoning from the input body velocities through the noise model, in the
//! odom frame, which coincides with the map frame at initialization (the odom origin is the
//! input pose then), as the built-in chassis's odometry does. The message is the chassis's
//! own (`agrisim_chassis::odometry::WheelOdometry::message`): frame ids odom / base_link, zero
//! covariances, stamped at the publication instant on simulation time with the pose at the
//! end of the step, so the two cannot drift apart in conventions.
//!
//! Each step integrates the velocities present at its start, held over the step, with the
//! SE(2) exponential map (`agrisim_chassis::se2::integrate`): exact for piecewise-constant
//! velocities, so straight lines and circles match their closed forms. Under the master's
//! Gauss-Seidel order (model before adapter) those are the model's velocities at the end of
//! its step, i.e. the ones a kinematic model held over that step.

use crate::noise::OdometryNoise;
use crate::ports::*;
use agrisim_chassis::odometry::WheelOdometry;
use agrisim_chassis::se2::{integrate, Twist2};
use agrisim_fmi::{Log, Model, OutPort, Store, Var};
use agrisim_math::{Pose2, Rng};
use agrisim_msgs::geometry_msgs::{Transform, TransformStamped, Vector3};
use agrisim_msgs::nav_msgs::Odometry;
use agrisim_msgs::tf2_msgs::TFMessage;
use agrisim_msgs::Message;
use agrisim_schedule::{to_ns, Schedule};

#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct ScalarsToOdometry {
    odom: WheelOdometry,
    noise: OdometryNoise,
    rng: Rng,
    schedule: Schedule,
    ports: Option<(OutPort, OutPort)>,
    window_ns: i64,
}

/// The transform an odometry message states (REP 105: odom -> base_link).
pub fn transform_of(m: &Odometry) -> TFMessage {
    let p = &m.pose.pose;
    TFMessage {
        transforms: vec![TransformStamped {
            header: m.header.clone(),
            child_frame_id: m.child_frame_id.clone(),
            transform: Transform {
                translation: Vector3 { x: p.position.x, y: p.position.y, z: p.position.z },
                rotation: p.orientation,
            },
        }],
    }
}

fn input_twist(io: &Store) -> Result<Twist2, String> {
    let t = Twist2 { vx: io.f64(VX), vy: io.f64(VY), wz: io.f64(WZ) };
    if t.vx.is_finite() && t.vy.is_finite() && t.wz.is_finite() {
        Ok(t)
    } else {
        Err(format!("non-finite velocity input {t:?}"))
    }
}

impl ScalarsToOdometry {
    fn write_outputs(&self, io: &mut Store) {
        io.set_f64(ODOM_X, self.odom.pose.x);
        io.set_f64(ODOM_Y, self.odom.pose.y);
        io.set_f64(ODOM_YAW, self.odom.pose.yaw);
        io.set_f64(ODOM_VX, self.odom.twist.vx);
        io.set_f64(ODOM_VY, self.odom.twist.vy);
        io.set_f64(ODOM_WZ, self.odom.twist.wz);
    }

    /// Publishes odom and tf when an instant of the schedule passed by `t`; syncs both ports.
    fn publish(&mut self, io: &mut Store, t: f64) {
        let (odom, tf) = self.ports.get_or_insert_with(|| (OutPort::new(ODOM, ODOM_SEQ), OutPort::new(TF, TF_SEQ)));
        if let Some(stamp) = self.schedule.due(t) {
            let m = self.odom.message(stamp);
            tf.publish(stamp, transform_of(&m).to_cdr());
            odom.publish(stamp, m.to_cdr());
        }
        odom.sync(io, to_ns(t), self.window_ns);
        tf.sync(io, to_ns(t), self.window_ns);
    }
}

impl Model for ScalarsToOdometry {
    const NAME: &'static str = "ScalarsToOdometry";
    const DESCRIPTION: &'static str =
        "Adapter: planar pose and body velocities in, nav_msgs/Odometry and odom -> base_link TF out, with seeded odometry noise";
    const VARIABLES: &'static [Var] = VARIABLES;

    agrisim_fmi::whole_state!();

    fn new() -> Self {
        Self::default()
    }

    fn initialize(&mut self, io: &mut Store, start_time: f64, _log: &mut dyn Log) -> Result<(), String> {
        let pose = Pose2 { x: io.f64(X), y: io.f64(Y), yaw: io.f64(YAW) };
        if !(pose.x.is_finite() && pose.y.is_finite() && pose.yaw.is_finite()) {
            return Err(format!("non-finite initial pose input {pose:?}"));
        }
        let noise = OdometryNoise {
            v_noise: io.f64(V_NOISE),
            wz_noise: io.f64(WZ_NOISE),
            v_scale_error: io.f64(V_SCALE_ERROR),
            wz_scale_error: io.f64(WZ_SCALE_ERROR),
        };
        for (name, v) in [("v_noise", noise.v_noise), ("wz_noise", noise.wz_noise)] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(format!("parameter {name} must be >= 0 and finite, got {v}"));
            }
        }
        *self = ScalarsToOdometry {
            odom: WheelOdometry { pose, twist: noise.scaled(input_twist(io)?) },
            noise,
            rng: Rng::new(io.i32(SEED) as u32 as u64),
            schedule: Schedule::new(io.f64(RATE), start_time)?,
            ports: None,
            window_ns: agrisim_fmi::port::window_ns(io, PORT_WINDOW)?,
        };
        self.write_outputs(io);
        self.publish(io, start_time);
        Ok(())
    }

    fn do_step(&mut self, io: &mut Store, t: f64, h: f64, _log: &mut dyn Log) -> Result<(), String> {
        let measured = self.noise.read(input_twist(io)?, &mut self.rng);
        self.odom.twist = measured;
        integrate(&mut self.odom.pose, measured, h);
        self.write_outputs(io);
        self.publish(io, t + h);
        Ok(())
    }
}
