//! What the harvest judges read, shared by the harvest and the row benchmark: the node's
//! reports (/harvest/plans, /harvest/status), plant touches and base contacts from
//! /collision, the world FMU's contact counters, and damage from /plant_damage. Nothing of the node's memory.

use super::setup::TrueFruit;
use agrisim_bus::Reader;
use agrisim_error::Result;
use agrisim_harvest::topics;
use agrisim_msgs::agrisim::{CollisionState, HarvestStatus, PlanResult, PlantDamage};
use agrisim_msgs::vision_msgs::Detection3DArray;
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

/// The fruit of `fruit` nearest `p`, and its distance [m].
pub(crate) fn nearest_fruit(fruit: &BTreeMap<u32, TrueFruit>, p: [f64; 3]) -> Option<(u32, f64)> {
    fruit
        .iter()
        .map(|(&id, f)| {
            let c = f.center;
            (id, ((c[0] - p[0]).powi(2) + (c[1] - p[1]).powi(2) + (c[2] - p[2]).powi(2)).sqrt())
        })
        .min_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)))
}

/// By sight: the node's target as it asks the mapper to leave it out (/harvest/allowed),
/// matched to the nearest true fruit.
pub(crate) struct Aims {
    reader: Reader,
}

/// One target the node aimed at: the nearest true fruit's id, the estimate's distance from its
/// centre [m], and the radius the node gave it [m].
#[derive(Debug, Clone, Copy)]
pub(crate) struct Aim {
    pub(crate) id: u32,
    pub(crate) error: f64,
    pub(crate) radius: f64,
}

impl Aims {
    pub(crate) fn subscribe(bus: &mut agrisim_bus::Bus) -> Aims {
        Aims { reader: Reader::subscribe(bus, agrisim_harvest::sight::topics::ALLOWED) }
    }

    /// The newest target sent since the last call. An empty array (the node clearing its
    /// target as a pick ends, in the exchange its outcome comes) is no target.
    pub(crate) fn newest(
        &mut self,
        bus: &mut agrisim_bus::Bus,
        fruit: &BTreeMap<u32, TrueFruit>,
    ) -> Result<Option<Aim>> {
        let mut aim = None;
        for a in self.reader.take::<Detection3DArray>(bus)? {
            if let Some(d) = a.detections.first() {
                let p = &d.bbox.center.position;
                aim = nearest_fruit(fruit, [p.x, p.y, p.z]).map(|(id, error)| Aim {
                    id,
                    error,
                    radius: 0.5 * d.bbox.size.x - agrisim_harvest::sight::ALLOWED_MARGIN,
                });
            }
        }
        Ok(aim)
    }
}

/// What passing through the crop cost (/plant_damage, world ground truth): leaves pressed
/// aside from rest, the largest force spent holding one [N], the largest main-stem load over
/// its strength. Flattened into the harvest and row trial records.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PlantEffects {
    #[serde(default)]
    pub leaf_pushes: u64,
    #[serde(default)]
    pub peak_leaf_force: f64,
    #[serde(default)]
    pub peak_stem_load: f64,
}

impl PlantEffects {
    /// Over several trials: pushes added, peaks the largest.
    pub fn total<'a>(all: impl IntoIterator<Item = &'a PlantEffects>) -> PlantEffects {
        all.into_iter().fold(PlantEffects::default(), |a, e| PlantEffects {
            leaf_pushes: a.leaf_pushes + e.leaf_pushes,
            peak_leaf_force: a.peak_leaf_force.max(e.peak_leaf_force),
            peak_stem_load: a.peak_stem_load.max(e.peak_stem_load),
        })
    }
}

/// What the judge keeps of /plant_damage: the last message and every pedicel break.
#[derive(Default)]
pub(crate) struct DamageLog {
    pub(crate) last: PlantDamage,
    pub(crate) mode: Option<String>,
    pub(crate) force: Option<f64>,
    pub(crate) moment: Option<f64>,
    pub(crate) events: Vec<(f64, f64)>,
}

impl DamageLog {
    /// Every /plant_damage message `reader` has got since the last call.
    pub(crate) fn read(&mut self, reader: &mut Reader, bus: &mut agrisim_bus::Bus) -> Result<()> {
        for d in reader.take::<PlantDamage>(bus)? {
            self.update(&d);
        }
        Ok(())
    }

    pub(crate) fn update(&mut self, d: &PlantDamage) {
        let breaks = |m: &PlantDamage| m.detached_by_pull + m.detached_by_bend + m.detached_by_twist;
        if breaks(d) > breaks(&self.last) && !d.last_detach_mode.is_empty() {
            self.mode = Some(d.last_detach_mode.clone());
            self.force = Some(self.force.map_or(d.last_detach_force, |f| f.max(d.last_detach_force)));
            self.moment = Some(self.moment.map_or(d.last_detach_moment, |f| f.max(d.last_detach_moment)));
            self.events.push((d.header.stamp.as_secs_f64(), d.last_detach_force));
        }
        self.last = d.clone();
    }

    pub(crate) fn effects(&self) -> PlantEffects {
        let d = &self.last;
        PlantEffects {
            leaf_pushes: d.leaf_pushes as u64,
            peak_leaf_force: d.peak_leaf_force,
            peak_stem_load: d.peak_stem_load,
        }
    }

    pub(crate) fn by_kind(&self) -> BTreeMap<String, u64> {
        let d = &self.last;
        [
            ("bruised_by_grip", d.bruised_by_grip),
            ("bruised_by_impact", d.bruised_by_impact),
            ("unripe_detached", d.unripe_detached),
            ("stems_broken", d.stems_broken),
        ]
        .into_iter()
        .map(|(k, v)| (k.to_string(), v as u64))
        .collect()
    }

    /// A bruised fruit (by impact only if `impact_fails`), a broken main stem or an unripe fruit
    /// detached fails the trial.
    pub(crate) fn failure(&self, impact_fails: bool) -> Option<String> {
        let d = &self.last;
        let bruised = d.bruised_by_grip + if impact_fails { d.bruised_by_impact } else { 0 };
        (bruised > 0 || d.stems_broken > 0 || d.unripe_detached > 0).then(|| {
            format!(
                "crop damaged: {} fruit bruised by grip, {} by impact, {} main stem(s) broken, {} unripe fruit detached",
                d.bruised_by_grip, d.bruised_by_impact, d.stems_broken, d.unripe_detached
            )
        })
    }
}

#[cfg(test)]
mod damage_tests {
    use super::*;

    /// `mode`: how the newest of the `pull` + `bend` breaks went.
    fn msg(pull: u32, bend: u32, mode: &str, force: f64, grip: u32) -> PlantDamage {
        PlantDamage {
            detached_by_pull: pull,
            detached_by_bend: bend,
            last_detach_mode: mode.into(),
            last_detach_force: force,
            bruised_by_grip: grip,
            ..Default::default()
        }
    }

    #[test]
    fn breaks_are_logged_once_and_bruises_fail() {
        let mut log = DamageLog::default();
        log.update(&msg(0, 0, "", 0.0, 0));
        assert_eq!(log.mode, None);
        assert_eq!(log.failure(true), None);
        log.update(&msg(0, 1, "bend", 6.0, 0));
        // The same break again (a republished message) is not a second event.
        log.update(&msg(0, 1, "bend", 6.0, 0));
        log.update(&msg(1, 1, "pull", 9.0, 0));
        assert_eq!(log.mode.as_deref(), Some("pull"));
        assert_eq!(log.force, Some(9.0));
        assert_eq!(log.events.len(), 2);
        assert_eq!(log.by_kind()["bruised_by_grip"], 0);
        log.update(&msg(1, 1, "pull", 9.0, 1));
        assert!(log.failure(false).unwrap().contains("1 fruit bruised by grip"));
        assert_eq!(log.by_kind()["bruised_by_grip"], 1);
        let mut impact = DamageLog::default();
        impact.update(&PlantDamage { bruised_by_impact: 1, ..Default::default() });
        assert_eq!(impact.failure(false), None);
        assert!(impact.failure(true).unwrap().contains("1 by impact"));
    }
}
