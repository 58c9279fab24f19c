//! The model: at every publication instant, a JointState of the configured joints from the
//! inputs present at the step (stamped with the instant, on simulation time, frame_id empty
//! as the Arm FMU's joint_states).

use crate::joints;
use crate::ports::*;
use agrisim_fmi::{Log, Model, OutPort, Store, Var};
use agrisim_msgs::builtin_interfaces::Time;
use agrisim_msgs::sensor_msgs::JointState;
use agrisim_msgs::std_msgs::Header;
use agrisim_msgs::Message;
use agrisim_schedule::{to_ns, Schedule};

#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct JointStateFromScalars {
    /// Derived from the parameters.
    joints: Vec<String>,
    with_velocity: bool,
    schedule: Schedule,
    port: Option<OutPort>,
    window_ns: i64,
}

impl JointStateFromScalars {
    fn message(&self, io: &Store, stamp_ns: i64) -> JointState {
        let n = self.joints.len();
        JointState {
            header: Header::new(Time::from_nanos(stamp_ns), ""),
            name: self.joints.clone(),
            position: Q[..n].iter().map(|&i| io.f64(i)).collect(),
            velocity: if self.with_velocity { QD[..n].iter().map(|&i| io.f64(i)).collect() } else { vec![] },
            effort: vec![],
        }
    }

    fn publish(&mut self, io: &mut Store, t: f64) {
        if let Some(stamp) = self.schedule.due(t) {
            let m = self.message(io, stamp).to_cdr();
            self.port.get_or_insert_with(|| OutPort::new(JOINT_STATES, JOINT_STATES_SEQ)).publish(stamp, m);
        }
        let port = self.port.get_or_insert_with(|| OutPort::new(JOINT_STATES, JOINT_STATES_SEQ));
        port.sync(io, to_ns(t), self.window_ns);
    }
}

impl Model for JointStateFromScalars {
    const NAME: &'static str = "JointStateFromScalars";
    const DESCRIPTION: &'static str =
        "Adapter: joint positions (and velocities) q1..q7 in, sensor_msgs/JointState out at a rate on simulation time";
    const VARIABLES: &'static [Var] = VARIABLES;

    agrisim_fmi::whole_state!();

    fn new() -> Self {
        Self::default()
    }

    fn initialize(&mut self, io: &mut Store, start_time: f64, _log: &mut dyn Log) -> Result<(), String> {
        *self = JointStateFromScalars {
            joints: joints::parse(io.string(JOINTS))?,
            with_velocity: io.bool(WITH_VELOCITY),
            schedule: Schedule::new(io.f64(RATE), start_time)?,
            port: None,
            window_ns: agrisim_fmi::port::window_ns(io, PORT_WINDOW)?,
        };
        self.publish(io, start_time);
        Ok(())
    }

    fn do_step(&mut self, io: &mut Store, t: f64, h: f64, _log: &mut dyn Log) -> Result<(), String> {
        self.publish(io, t + h);
        Ok(())
    }
}
