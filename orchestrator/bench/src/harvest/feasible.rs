//! Whether a trial's task was within the robot's hand at all: a ripe fruit of the task no
//! wider than the hand opens. A crop whose fruit are wider than the gripper (the family draws
//! mean radii up to 40 mm, and single fruit to 56 mm) gives tasks no method could do with this
//! hand; the summary reports them apart, beside the rate over every trial, which stays the
//! headline.

use super::setup::TrueFruit;
use super::targets::RIPE_STAGE;
use super::trial::HarvestTrial;
use agrisim_harvest::sight::Region;
use std::collections::BTreeMap;

/// The largest fruit radius the hand can close round [m]: half the Franka Hand's 80 mm
/// opening between its pads (`agrisim_harvest::geometry::OPEN_WIDTH`).
pub const HAND_RADIUS: f64 = 0.5 * agrisim_harvest::geometry::OPEN_WIDTH;

/// Whether trial `t`'s task offered a fruit the hand can hold: by sight, a ripe fruit of its
/// region with a true radius of at most [`HAND_RADIUS`]; handed a fruit, that fruit's radius.
/// From the world's ground truth (the scene's fruit by object id), for judging only.
pub fn hand_can_do(fruit: &BTreeMap<u32, TrueFruit>, t: &HarvestTrial) -> bool {
    match t.region {
        Some([x, y, z]) => {
            let region = Region { x, y, z };
            fruit.values().any(|f| f.stage >= RIPE_STAGE && f.radius <= HAND_RADIUS && region.contains(f.center))
        }
        None => fruit.get(&t.fruit_id).is_some_and(|f| f.radius <= HAND_RADIUS),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::harvest::targets::{HarvestTarget, Visibility};

    fn setup(fruit: &[(u32, u8, [f64; 3], f64)]) -> BTreeMap<u32, TrueFruit> {
        fruit.iter().map(|&(id, stage, center, radius)| (id, TrueFruit { stage, center, radius })).collect()
    }

    fn trial(id: u32, region: Option<[[f64; 2]; 3]>) -> HarvestTrial {
        let target = HarvestTarget {
            fruit_index: 0,
            object_id: id,
            name: "f".into(),
            center: [0.0; 3],
            radius: 0.03,
            side: 1.0,
            visibility: Visibility::Free,
            start: [0.0; 3],
        };
        HarvestTrial { region, sight: region.is_some(), ..HarvestTrial::of_target(0, 1, &target) }
    }

    #[test]
    fn a_task_is_beyond_the_hand_when_its_ripe_fruit_are_all_wider_than_it_opens() {
        let region = Some([[0.0, 1.0], [0.0, 1.0], [0.5, 1.5]]);
        // In the region: a wide ripe fruit, a narrow unripe one; outside: a narrow ripe one.
        let s = setup(&[(1, 6, [0.5, 0.5, 1.0], 0.042), (2, 3, [0.4, 0.5, 1.0], 0.03), (3, 6, [1.5, 0.5, 1.0], 0.03)]);
        assert!(!hand_can_do(&s, &trial(1, region)));
        assert!(!hand_can_do(&s, &trial(1, None)));
        assert!(hand_can_do(&s, &trial(3, None)));
        // A ripe fruit just as wide as the hand opens is within it.
        let s = setup(&[(1, 6, [0.5, 0.5, 1.0], 0.042), (4, 5, [0.6, 0.2, 0.7], HAND_RADIUS)]);
        assert!(hand_can_do(&s, &trial(1, region)));
        assert!(!hand_can_do(&s, &trial(9, None)), "an unknown fruit is not");
    }
}
