//! The harvest task's stages and the paper's failure categories.

/// Stages in order; each is reported on `/harvest/status` when entered.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Stage {
    /// Between two fruit of a row: let go of anything held, both arms home.
    Recover,
    SelectTarget,
    PositionBase,
    PreGrasp,
    Approach,
    Grasp,
    /// Open, back off and approach again after the gripper closed on nothing.
    Regrasp,
    /// Bend the held fruit off its plant (a wrist roll about the approach axis, which turns the
    /// fruit about a horizontal axis through its centre: bending at the pedicel), and check by
    /// the arm's joint torques whether it came off; the retreat pulls (the fallback) otherwise.
    Detach,
    Retreat,
    HandoverPose,
    Handover,
    Transfer,
    Release,
    Done,
    Failed,
}

impl Stage {
    pub fn name(self) -> &'static str {
        match self {
            Stage::Recover => "recover",
            Stage::SelectTarget => "select_target",
            Stage::PositionBase => "position_base",
            Stage::PreGrasp => "pre_grasp",
            Stage::Approach => "approach",
            Stage::Grasp => "grasp",
            Stage::Regrasp => "regrasp",
            Stage::Detach => "detach",
            Stage::Retreat => "retreat",
            Stage::HandoverPose => "handover_pose",
            Stage::Handover => "handover",
            Stage::Transfer => "transfer",
            Stage::Release => "release",
            Stage::Done => "done",
            Stage::Failed => "failed",
        }
    }
}

/// Why a harvest failed: the paper's four categories plus timeout and collision.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Failure {
    /// No IK solution, no collision-free path, or a trajectory that breaks a limit.
    Planning,
    /// The gripper closed on nothing or lost the fruit before the handover.
    Grasp,
    /// The second gripper did not take the fruit, or it fell during the exchange.
    Handover,
    /// The released fruit did not end up in the box.
    Placement,
    Timeout,
    Collision,
    /// By sight: no ripe fruit was found in the task's region.
    NotDetected,
    /// By sight: the region's ripe fruit were found, every one wider than the hand opens.
    TooWide,
}

impl Failure {
    pub fn name(self) -> &'static str {
        match self {
            Failure::Planning => "planning",
            Failure::Grasp => "grasp",
            Failure::Handover => "handover",
            Failure::Placement => "placement",
            Failure::Timeout => "timeout",
            Failure::Collision => "collision",
            Failure::NotDetected => "not_detected",
            Failure::TooWide => "too_wide",
        }
    }
}
