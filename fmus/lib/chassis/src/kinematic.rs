//! Kinematic drive: wheels follow their set-points exactly; the base moves as the wheels'
//! contact velocities dictate, less a seeded longitudinal slip.

use crate::chassis::{mean_contact_velocities, Drive, StepInput, StepOutput};
use crate::ports::*;
use crate::se2::Twist2;
use crate::wheels::WheelState;
use agrisim_fmi::Store;

#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct KinematicDrive {
    slip_mean: f64,
    slip_std: f64,
}

impl Drive for KinematicDrive {
    const NAME: &'static str = "ChassisKinematic";
    const DESCRIPTION: &'static str = "4-wheel-steering omnidirectional base, kinematic model with steering-rate, wheel-speed and acceleration limits, slip and wheel odometry";

    fn initialize(&mut self, io: &Store) -> Result<(), String> {
        self.slip_mean = io.f64(SLIP_MEAN);
        self.slip_std = io.f64(SLIP_STD);
        if !(self.slip_mean.is_finite() && self.slip_mean.abs() < 1.0) {
            return Err(format!("parameter slip_mean must lie in (-1, 1), got {}", self.slip_mean));
        }
        Ok(())
    }

    fn step(&mut self, wheels: &mut [WheelState; 4], _base: Twist2, input: StepInput<'_>) -> StepOutput {
        let start = *wheels;
        *wheels = *input.reference;
        let travel = mean_contact_velocities(input.layout, &start, wheels, input.ramp);
        // Slip: the ground moves by (1 - s) of what the wheel rolls; one draw per wheel and step.
        let slip: [f64; 4] = std::array::from_fn(|_| 1.0 - self.slip_mean - input.rng.gauss(self.slip_std));
        let moved: [(f64, f64); 4] = std::array::from_fn(|i| (travel[i].0 * slip[i], travel[i].1 * slip[i]));
        let end_v = input.layout.wheel_velocities(wheels);
        let end_moved: [(f64, f64); 4] = std::array::from_fn(|i| (end_v[i].0 * slip[i], end_v[i].1 * slip[i]));
        StepOutput {
            mean: input.layout.forward_from_velocities(&moved),
            end: input.layout.forward_from_velocities(&end_moved),
            wheel_travel: travel,
        }
    }
}

/// The kinematic chassis model (FMU `ChassisKinematic`).
pub type ChassisKinematic = crate::chassis::Chassis<KinematicDrive>;
