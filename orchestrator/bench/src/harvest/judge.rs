//! What the harvest judges read, shared by the harvest and the row benchmark: the node's
//! reports (/harvest/plans, /harvest/status), plant touches and base contacts from
//! /collision, and the world FMU's contact counters. Nothing of the node's memory.

use agrisim_bus::Reader;
use agrisim_error::Result;
use agrisim_harvest::topics;
use agrisim_msgs::agrisim::{CollisionState, HarvestStatus, PlanResult};
use std::collections::BTreeMap;

/// Onsets of contact with scene objects, by kind, from /collision messages.
#[derive(Default)]
pub(crate) struct Touches {
    /// Objects in contact in the last message.
    now: std::collections::BTreeSet<u32>,
    pub(crate) by_kind: BTreeMap<String, u64>,
}

impl Touches {
    /// Counts every object in `cs` not touched in the previous message, except the task's
    /// own fruit (`picked`).
    pub(crate) fn update(&mut self, cs: &CollisionState, picked: impl Fn(u32) -> bool) {
        let mut next = std::collections::BTreeSet::new();
        for c in &cs.contacts {
            // Arm-arm and carried-fruit contacts are failures, judged from the world's counters.
            if picked(c.object_id)
                || c.object_kind == "robot_arm"
                || c.robot_link == "carried_fruit"
                || !next.insert(c.object_id)
            {
                continue;
            }
            if !self.now.contains(&c.object_id) {
                *self.by_kind.entry(c.object_kind.clone()).or_insert(0) += 1;
            }
        }
        self.now = next;
    }
}

/// The failure a base contact in `cs` is, if any: the base must touch nothing.
pub(crate) fn base_contact(cs: &CollisionState) -> Option<String> {
    cs.contacts
        .iter()
        .find(|c| c.robot_link == "base_link")
        .map(|c| format!("the base touched {} ({})", c.object_name, c.object_kind))
}

/// Contact counters of the world FMU that end a trial as a collision (judged after every
/// exchange from counters the world updates every step): the robot or a fruit it carries
/// against the structure, arm against arm.
pub const COLLISION_COUNTERS: [&str; 3] = ["contact_robot_structure", "contact_arm_arm", "contact_carried_structure"];
/// Counted but expected: leaves and trusses brush the arm.
pub const SOFT_COUNTERS: [&str; 1] = ["contact_robot_plant"];

/// The judge's view of the harvest node: only what it published.
pub(crate) struct Reports {
    plans_reader: Reader,
    status_reader: Reader,
    pub(crate) plans: Vec<PlanResult>,
    /// Wall time of each plan [s]: the node's step that asked for it, shared among the plans
    /// of that step.
    pub(crate) planning_times: Vec<f64>,
    /// The final status (outcome success or failure), once published.
    pub(crate) outcome: Option<HarvestStatus>,
}

impl Reports {
    pub(crate) fn subscribe(bus: &mut agrisim_bus::Bus) -> Reports {
        Reports {
            plans_reader: Reader::subscribe(bus, topics::PLANS),
            status_reader: Reader::subscribe(bus, topics::STATUS),
            plans: vec![],
            planning_times: vec![],
            outcome: None,
        }
    }

    /// Takes everything the node published since the last look.
    pub(crate) fn read(&mut self, m: &mut agrisim_session::Session, node: &str) -> Result<()> {
        let plans: Vec<PlanResult> = self.plans_reader.take(&mut m.bus)?;
        if !plans.is_empty() {
            // An external node (over ROS 2) is not timed here: no planning times for it.
            if let Some(wall) = m.node_wall(node) {
                self.planning_times.extend(std::iter::repeat_n(wall / plans.len() as f64, plans.len()));
            }
            self.plans.extend(plans);
        }
        for st in self.status_reader.take::<HarvestStatus>(&mut m.bus)? {
            if self.outcome.is_none() && (st.outcome == "success" || st.outcome == "failure") {
                self.outcome = Some(st);
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use agrisim_msgs::agrisim::Contact;

    fn state(contacts: &[(u32, &str, &str)]) -> CollisionState {
        CollisionState {
            contacts: contacts
                .iter()
                .map(|&(id, kind, link)| Contact {
                    object_id: id,
                    object_kind: kind.into(),
                    robot_link: link.into(),
                    ..Contact::default()
                })
                .collect(),
            ..CollisionState::default()
        }
    }

    /// An object counts once per onset, however many links touch it and however long; the
    /// target fruit, arm-arm and carried-fruit contacts (failures, not touches) do not
    /// count; letting go and touching again does.
    #[test]
    fn touches_count_onsets_by_kind() {
        let mut t = Touches::default();
        t.update(&state(&[(5, "leaf", "left_link5"), (5, "leaf", "left_link6"), (9, "fruit", "left_hand")]), |id| {
            id == 9
        });
        t.update(
            &state(&[
                (5, "leaf", "left_link5"),
                (7, "stem", "left_link4"),
                (0, "robot_arm", "left_link7"),
                (13, "post", "carried_fruit"),
            ]),
            |id| id == 9,
        );
        t.update(&state(&[]), |id| id == 9);
        t.update(&state(&[(5, "leaf", "left_link5"), (11, "fruit", "right_hand")]), |id| id == 9);
        assert_eq!(
            t.by_kind,
            BTreeMap::from([("leaf".to_string(), 2), ("stem".to_string(), 1), ("fruit".to_string(), 1)])
        );
    }
}
