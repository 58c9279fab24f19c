//! `agrisim.ArmModel`: forward kinematics of one arm from the robot URDF the FMUs are built
//! from (models/robot/agrisim_robot.urdf), for environments and policies that need the tool
//! centre point of a joint configuration.

use crate::py_err;
use agrisim_robot::{Joint, Robot};
use pyo3::prelude::*;

const URDF: &str = include_str!("../../models/robot/agrisim_robot.urdf");

#[pyclass(frozen, module = "agrisim._agrisim")]
pub struct ArmModel {
    chain: Vec<Joint>,
    /// Movable joints of the chain other than the lift, in chain order.
    arm: Vec<usize>,
    lift: f64,
}

#[pymethods]
impl ArmModel {
    /// Arm `side` ("left" or "right") from `base_link` to `{side}_hand_tcp`, with the lift at
    /// `lift` [m].
    #[new]
    #[pyo3(signature = (side="left", lift=0.0))]
    fn new(side: &str, lift: f64) -> PyResult<ArmModel> {
        if side != "left" && side != "right" {
            return Err(py_err(format!("arm side '{side}': expected left or right")));
        }
        let robot = Robot::from_urdf_str(URDF).map_err(|e| py_err(format!("models/robot/agrisim_robot.urdf: {e}")))?;
        let chain = robot.chain(&robot.root, &format!("{side}_hand_tcp")).map_err(py_err)?;
        let arm = chain
            .iter()
            .enumerate()
            .filter(|(_, j)| j.kind.is_movable() && j.name != "lift_joint")
            .map(|(i, _)| i)
            .collect();
        Ok(ArmModel { chain, arm, lift })
    }

    /// The arm's joint names, in order.
    #[getter]
    fn joint_names(&self) -> Vec<String> {
        self.arm.iter().map(|&i| self.chain[i].name.clone()).collect()
    }

    /// Lower and upper position limits [rad] of the arm's joints.
    #[getter]
    fn limits(&self) -> (Vec<f64>, Vec<f64>) {
        self.arm
            .iter()
            .map(|&i| self.chain[i].limits.map_or((f64::NEG_INFINITY, f64::INFINITY), |l| (l.lower, l.upper)))
            .unzip()
    }

    /// The tool centre point for joint positions `q` (one per arm joint): its position [m]
    /// and row-major rotation in `base_link`.
    fn fk(&self, q: Vec<f64>) -> PyResult<([f64; 3], [[f64; 3]; 3])> {
        if q.len() != self.arm.len() {
            return Err(py_err(format!("fk: {} joint values for {} arm joints", q.len(), self.arm.len())));
        }
        let mut it = q.iter();
        let values: Vec<f64> = self
            .chain
            .iter()
            .filter(|j| j.kind.is_movable())
            .map(|j| if j.name == "lift_joint" { self.lift } else { *it.next().expect("counted") })
            .collect();
        let p = Robot::chain_fk(&self.chain, &values).map_err(py_err)?;
        Ok((p.trans, p.rot))
    }
}
