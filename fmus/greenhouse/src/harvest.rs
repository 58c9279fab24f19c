//! Harvest physics: grasping, carrying, handing over, releasing and placing fruit.
//!
//! Rules (the FMU's contract; lengths in m):
//! - **Attach**: a gripper attaches a fruit when its gap decreases this step (`w < w_prev`),
//!   the fruit fitted between the open fingers (`w_prev >= d - tol`), the fingers are now at
//!   or inside the fruit (`w <= d + tol`), and the fruit centre lies between the pads in the
//!   hand frame: along the approach axis within the pad length, sideways within the pad depth
//!   (both from the URDF finger geometry, widened by `tol`), and across within `w_prev / 2`.
//!   `d` is the fruit diameter, `tol` the `grasp_tolerance` parameter. Several candidates:
//!   the one nearest the pad centre. The symmetric fingers centre a free fruit between them
//!   (it moves along the closing axis to the middle); a fruit the other gripper holds stays
//!   where it is.
//! - **Detach** ([`crate::pedicel`]): a fruit grasped on its plant stays attached to its
//!   truss by its pedicel, a spring-damper joint that loads the hand, until the pull, bend or
//!   twist at its abscission zone exceeds the fruit's threshold; it is picked (counted) then.
//!   Opened before that, the gripper leaves it on the plant (it springs back to its rest pose).
//!   With the pedicel off (`pedicel_enabled = false`) a fruit is picked when the fingers close.
//! - **Carry**: a held fruit (attached or picked) follows the hand that grasped it first,
//!   rigidly, at the relative pose it had when grasped.
//! - **Handover**: a fruit held by one gripper can be grasped by the other by the same rule;
//!   it is then held by both, still following the first; when the first opens it follows
//!   the second.
//! - **Release**: a gripper lets go when its gap exceeds `d + release_margin`, or, for a fruit
//!   within that margin of the widest gap the fingers open to, when they are open all the way
//!   (a 77 mm fruit in the 80 mm Franka gap is no longer squeezed; with the margin alone it
//!   stayed in the hand for good, and every later grasp of a row closed on it). If no other
//!   gripper holds the fruit, it becomes a dynamic rapier body (gravity, contacts, CCD) with
//!   the hand's velocity.
//! - **Settle**: a falling fruit whose lowest point reaches the floor (z <= 5 mm) is dropped.
//!   One that moves slower than `REST_SPEED` relative to the harvest box for `REST_TIME`
//!   (or still falls after `MAX_FALL_TIME`) has come to rest: with its centre inside the box
//!   interior (harvest_box_link frame, from the URDF) it is placed and from then on rides
//!   in the box; elsewhere (a leaf, a pipe, the robot's top) it is dropped and frozen there.
//!   A dropped fruit can be grasped again; a placed one cannot.
//! - **Damage** (ground truth, [`Damage`]): a fruit is bruised when a gripper holding it
//!   squeezes with more than `bruise_grip_force`, or when a released fruit reaches more than
//!   `bruise_impact_speed` before it settles (its impact on the box, the floor or a leaf); a
//!   picked fruit below `ripe_stage` is an unripe fruit detached. Each fruit counts once per kind.
//!   A main stem a robot part presses on beyond its bending strength is broken
//!   ([`crate::stems`]); each stem counts once.

use crate::pedicel::{Attachment, Load, Mode, PedicelGeometry, PedicelParams};
use crate::robot_links::{from_rapier, to_rapier};
use crate::robot_model::{BoxInterior, FingerPads, Side};
use crate::scene_world::SceneWorld;
use crate::stems::{StemLoad, StemParams};
use agrisim_math::vec3::{norm, sub};
use agrisim_robot::Pose as RPose;
use agrisim_scene::scene::Kind;
use rapier3d::parry::bounding_volume::Aabb;
use rapier3d::prelude::*;
use std::collections::{BTreeMap, BTreeSet};

/// Speed [m/s] relative to the box below which a released fruit counts as resting.
pub const REST_SPEED: f64 = 0.02;
/// How long [s] a released fruit must rest before it is placed or dropped.
pub const REST_TIME: f64 = 0.2;
/// A released fruit still moving after this long [s] is settled where it is.
pub const MAX_FALL_TIME: f64 = 10.0;
/// Height [m] of a fruit's lowest point at which it has landed on the floor (floor top z = 0).
pub const FLOOR_EPS: f64 = 0.005;

/// Where a fruit is in the harvest.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum FruitState {
    OnPlant,
    /// Held by one or both grippers, following `leader`'s hand.
    Held {
        leader: Side,
    },
    /// Released and under gravity; `rest` = time spent resting so far, `airborne` since release.
    Falling {
        rest: f64,
        airborne: f64,
    },
    /// At rest inside the harvest box, at pose `in_box` in harvest_box_link.
    Placed {
        in_box: RPose,
    },
    /// At rest anywhere but the box (frozen there).
    Dropped,
}

#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Gripper {
    /// Gap at the end of the last step [m].
    pub width: f64,
    /// Fruit-list index of the fruit this gripper holds.
    pub held: Option<usize>,
    /// The held fruit's pose in the hand frame.
    pub grip: RPose,
}

#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct HarvestParams {
    pub grasp_tolerance: f64,
    pub release_margin: f64,
    pub pedicel: PedicelParams,
    /// Seed of the per-fruit pedicel thresholds (the scene's seed).
    pub seed: u64,
    pub damage: DamageParams,
}

impl HarvestParams {
    /// The given grasp rules with the default pedicel and damage figures.
    pub fn new(grasp_tolerance: f64, release_margin: f64) -> HarvestParams {
        HarvestParams {
            grasp_tolerance,
            release_margin,
            pedicel: PedicelParams::default(),
            seed: 0,
            damage: DamageParams::default(),
        }
    }
}

/// Damage thresholds (the FMU's `bruise_*` and `ripe_stage` parameters).
///
/// - `bruise_grip_force`, default 40 N: an estimate. Tomato flesh yields in compression
///   between two flat plates at some tens of N for firm-ripe fruit and less as it ripens
///   (Zheng et al., "Study on Mechanical Properties of Tomatoes for the End-Effector Design
///   of the Harvesting Robot", Agriculture 13(12) 2201, 2023; Li et al., J. Food Eng. 111(1)
///   82-91, 2012); the Franka Hand's 70 N continuous force (datasheet) is above it, the
///   harvest node's 20 N below.
/// - `bruise_impact_speed`, default 2.0 m/s (a free fall of 0.2 m): tomatoes dropped 20 cm
///   or more onto a hard surface develop internal bruising (Sargent, Brecht and Zoellner,
///   "Sensitivity of tomatoes at mature-green and breaker ripeness to internal bruising",
///   J. Amer. Soc. Hort. Sci. 117(1) 119-123, 1992); Lee et al., HortScience 53(9) 1352,
///   2018, measured the severest impacts (> 10 g) when fruit go into and out of harvest boxes.
/// - `ripe_stage`, default 5: USDA stage 5 (light red) and 6 (red) are ripe, as the harvest
///   benchmark's targets.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct DamageParams {
    pub bruise_grip_force: f64,
    pub bruise_impact_speed: f64,
    pub ripe_stage: u8,
    /// Main stems' stiffness and strength ([`crate::stems`]).
    pub stem: StemParams,
}

impl Default for DamageParams {
    fn default() -> Self {
        DamageParams { bruise_grip_force: 40.0, bruise_impact_speed: 2.0, ripe_stage: 5, stem: StemParams::default() }
    }
}

/// Damage so far: fruit indices by kind (each fruit once per kind).
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Damage {
    pub grip_bruised: BTreeSet<usize>,
    pub impact_bruised: BTreeSet<usize>,
    pub unripe_detached: BTreeSet<usize>,
    /// The largest grip force that bruised a fruit [N] and the fastest impact that did [m/s].
    pub peak_grip: f64,
    pub peak_impact: f64,
    /// Broken main stems (scene object indices).
    pub stems_broken: BTreeSet<usize>,
    /// The largest stem load so far, as a fraction of its bending strength, and its force [N].
    pub peak_stem_ratio: f64,
    pub peak_stem_force: f64,
}

impl Damage {
    /// Fruit bruised by grip or impact (each once).
    pub fn bruised(&self) -> usize {
        self.grip_bruised.union(&self.impact_bruised).count()
    }

    /// Takes this step's stem loads (by stem object index): a load at or above the stem's
    /// strength breaks it.
    pub fn press_stems(&mut self, loads: &[(usize, StemLoad)]) {
        for &(object, load) in loads {
            if load.ratio >= 1.0 {
                self.stems_broken.insert(object);
            }
            if load.ratio > self.peak_stem_ratio {
                (self.peak_stem_ratio, self.peak_stem_force) = (load.ratio, load.force);
            }
        }
    }
}

/// How the last pedicel broke.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Detachment {
    pub fruit: usize,
    pub mode: Mode,
    /// The load in the step it broke.
    pub load: Load,
}

#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct Harvest {
    pub params: HarvestParams,
    /// States of the fruit that left their plant (absent = on the plant), by fruit index.
    fruit: BTreeMap<usize, FruitState>,
    pub grippers: [Gripper; 2],
    /// Hand poses (map frame) of the last step: the velocity a released fruit inherits.
    prev_hands: [RPose; 2],
    pub picked: u32,
    pub placed: u32,
    pub dropped: u32,
    pub last_placed: Option<usize>,
    /// Grasped fruit still on their plant, by fruit index.
    pub attached: BTreeMap<usize, Attachment>,
    /// The pedicel load on the fruit each gripper holds, this step (None: nothing attached).
    pub loads: [Option<Load>; 2],
    /// Grip force each gripper squeezes with [N] (the arm FMU's, an input).
    pub grip_forces: [f64; 2],
    pub last_detachment: Option<Detachment>,
    /// Pedicels broken by pull, bend and twist.
    pub detached_by: [u32; 3],
    pub damage: Damage,
    /// Fastest speed of each falling fruit so far [m/s].
    fall_speed: BTreeMap<usize, f64>,
}

/// Whether fingers at gap `w` let go of a fruit of diameter `d` (see the module's rules).
fn releases(w: f64, d: f64, margin: f64, max_gap: f64) -> bool {
    w > d + margin || (w >= max_gap - 1e-6 && w > d)
}

impl Harvest {
    pub fn new(params: HarvestParams, widths: [f64; 2], hands: [RPose; 2]) -> Harvest {
        let gripper = |w| Gripper { width: w, held: None, grip: RPose::IDENTITY };
        Harvest {
            params,
            fruit: BTreeMap::new(),
            grippers: [gripper(widths[0]), gripper(widths[1])],
            prev_hands: hands,
            picked: 0,
            placed: 0,
            dropped: 0,
            last_placed: None,
            attached: BTreeMap::new(),
            loads: [None; 2],
            grip_forces: [0.0; 2],
            last_detachment: None,
            detached_by: [0; 3],
            damage: Damage::default(),
            fall_speed: BTreeMap::new(),
        }
    }

    /// Whether fruit `f` is grasped but still on its plant.
    pub fn is_attached(&self, f: usize) -> bool {
        self.attached.contains_key(&f)
    }

    pub fn state(&self, fruit: usize) -> FruitState {
        self.fruit.get(&fruit).copied().unwrap_or(FruitState::OnPlant)
    }

    /// Whether touching this fruit is touching the crop (on its plant, or lying where it fell),
    /// rather than the load the robot carries or is releasing.
    pub fn counts_as_plant(&self, fruit: usize) -> bool {
        matches!(self.state(fruit), FruitState::OnPlant | FruitState::Dropped)
    }

    /// Fruit-list indices of the fruit the grippers hold, each once (both hold it in a handover).
    pub fn carried(&self) -> impl Iterator<Item = usize> {
        let [left, right] = self.grippers.map(|g| g.held);
        left.into_iter().chain(right.filter(|&f| Some(f) != left))
    }

    pub fn any_falling(&self) -> bool {
        self.fruit.values().any(|s| matches!(s, FruitState::Falling { .. }))
    }

    /// Grasp width [m] a gripper reports: the held fruit's diameter, 0 when empty.
    pub fn grasp_width(&self, world: &SceneWorld, side: Side) -> f64 {
        self.grippers[side as usize].held.map_or(0.0, |f| 2.0 * world.fruit[f].radius)
    }

    /// Applies the attach/release rules for both grippers (left first) with the hands at
    /// `hands` (map frame) and the finger gaps `widths`, for a step of `h` seconds.
    pub fn grip(
        &mut self,
        world: &mut SceneWorld,
        pads: &[FingerPads; 2],
        pedicels: &[PedicelGeometry],
        hands: &[RPose; 2],
        widths: [f64; 2],
        h: f64,
    ) {
        for side in Side::BOTH {
            let s = side as usize;
            let (w, prev) = (widths[s], self.grippers[s].width);
            if let Some(f) = self.grippers[s].held {
                if releases(w, 2.0 * world.fruit[f].radius, self.params.release_margin, pads[s].max_gap()) {
                    self.release(world, side, f, hands, h);
                }
            } else if w < prev {
                if let Some(f) = self.candidate(world, &pads[s], &hands[s], w, prev) {
                    self.attach(world, side, f, &hands[s], pedicels);
                }
            }
            self.grippers[s].width = w;
        }
        self.prev_hands = *hands;
    }

    /// The fruit a closing gripper (gap `prev` -> `w`) closes on, if any.
    fn candidate(&self, world: &SceneWorld, pads: &FingerPads, hand: &RPose, w: f64, prev: f64) -> Option<usize> {
        let tol = self.params.grasp_tolerance;
        let (xs, zs) = ([pads.x[0] - tol, pads.x[1] + tol], [pads.z[0] - tol, pads.z[1] + tol]);
        let half = 0.5 * prev;
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for x in xs {
            for y in [-half, half] {
                for z in zs {
                    let p = hand.transform_point([x, y, z]);
                    for i in 0..3 {
                        lo[i] = lo[i].min(p[i]);
                        hi[i] = hi[i].max(p[i]);
                    }
                }
            }
        }
        let aabb = Aabb::new(
            Vector::new(lo[0] as Real, lo[1] as Real, lo[2] as Real),
            Vector::new(hi[0] as Real, hi[1] as Real, hi[2] as Real),
        );
        let centre = [0.5 * (pads.x[0] + pads.x[1]), 0.0, 0.5 * (pads.z[0] + pads.z[1])];
        let inv = hand.inverse();
        let qp = world.query_pipeline();
        let mut found: Vec<(f64, usize)> = Vec::new();
        for (_, collider) in qp.intersect_aabb_conservative(aabb) {
            let Some(f) = world.object_of(collider).and_then(|o| world.fruit_of_object(o)) else { continue };
            if matches!(self.state(f), FruitState::Placed { .. }) {
                continue;
            }
            let d = 2.0 * world.fruit[f].radius;
            let c = inv.transform_point(from_rapier(&world.fruit_pose(f)).trans);
            let between = c[0] >= xs[0] && c[0] <= xs[1] && c[2] >= zs[0] && c[2] <= zs[1] && c[1].abs() <= half;
            if between && prev >= d - tol && w <= d + tol {
                found.push((norm(sub(c, centre)), f));
            }
        }
        found.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        found.first().map(|&(_, f)| f)
    }

    fn attach(&mut self, world: &mut SceneWorld, side: Side, f: usize, hand: &RPose, pedicels: &[PedicelGeometry]) {
        let body = world.fruit[f].body;
        let pose = from_rapier(world.bodies[body].position());
        let state = self.state(f);
        match state {
            FruitState::Held { .. } => {}
            FruitState::OnPlant | FruitState::Falling { .. } | FruitState::Dropped | FruitState::Placed { .. } => {
                if state == FruitState::OnPlant {
                    if self.params.pedicel.enabled {
                        let geom = pedicels.get(f).copied().unwrap_or(PedicelGeometry::VERTICAL);
                        let t = self.params.pedicel.thresholds(self.params.seed, f);
                        self.attached.insert(f, Attachment::new(pose, world.fruit[f].radius, geom, t));
                    } else {
                        self.detached(world, f, None);
                    }
                }
                let b = &mut world.bodies[body];
                b.set_body_type(RigidBodyType::KinematicPositionBased, true);
                b.enable_ccd(false);
                self.fruit.insert(f, FruitState::Held { leader: side });
            }
        }
        let g = &mut self.grippers[side as usize];
        g.held = Some(f);
        g.grip = hand.inverse().mul(&pose);
        // Franka's fingers move symmetrically: closing on a free fruit pushes it to the
        // middle between them (hand y = 0). A fruit the other gripper holds stays put.
        if !matches!(state, FruitState::Held { .. }) {
            g.grip.trans[1] = 0.0;
        }
    }

    fn release(&mut self, world: &mut SceneWorld, side: Side, f: usize, hands: &[RPose; 2], h: f64) {
        let s = side as usize;
        let grip = self.grippers[s].grip;
        self.grippers[s].held = None;
        let other = side.other();
        if self.grippers[other as usize].held == Some(f) {
            self.fruit.insert(f, FruitState::Held { leader: other });
            return;
        }
        // Still on its plant: the pedicel takes it back to where it hung.
        if let Some(a) = self.attached.remove(&f) {
            let b = &mut world.bodies[world.fruit[f].body];
            b.set_body_type(RigidBodyType::Fixed, true);
            b.set_position(to_rapier(&a.rest), true);
            self.fruit.remove(&f);
            return;
        }
        // The fruit is where the hand put it last step; it leaves with the hand's velocity.
        let (from, to) = (self.prev_hands[s].mul(&grip).trans, hands[s].mul(&grip).trans);
        let v = sub(to, from).map(|d| (d / h) as Real);
        let b = &mut world.bodies[world.fruit[f].body];
        b.set_body_type(RigidBodyType::Dynamic, true);
        b.enable_ccd(true);
        b.set_linvel(Vector::new(v[0], v[1], v[2]), true);
        b.set_angvel(Vector::ZERO, true);
        self.fruit.insert(f, FruitState::Falling { rest: 0.0, airborne: 0.0 });
        self.fall_speed.insert(f, 0.0);
    }

    /// A pedicel broke (or, with the pedicel off, a fruit was grasped): fruit `f` is picked.
    fn detached(&mut self, world: &SceneWorld, f: usize, how: Option<(Mode, Load)>) {
        self.picked += 1;
        if let Kind::Fruit { ripeness } = world.objects[world.fruit[f].object].kind {
            if ripeness < self.params.damage.ripe_stage {
                self.damage.unripe_detached.insert(f);
            }
        }
        if let Some((mode, load)) = how {
            self.detached_by[mode.code() as usize - 1] += 1;
            self.last_detachment = Some(Detachment { fruit: f, mode, load });
        }
    }

    /// The pedicel loads of the attached fruit with the hands at `hands` after a step of `h`
    /// s: each either holds (its load is on the hands holding it) or breaks (the fruit is
    /// picked). Then grip bruising with the grippers' forces `grip_forces`.
    pub fn pull(&mut self, world: &SceneWorld, hands: &[RPose; 2], grip_forces: [f64; 2], h: f64) {
        self.loads = [None; 2];
        self.grip_forces = grip_forces;
        let attached: Vec<usize> = self.attached.keys().copied().collect();
        for f in attached {
            let FruitState::Held { leader } = self.state(f) else { continue };
            let l = leader as usize;
            let pose = hands[l].mul(&self.grippers[l].grip);
            let p = self.params.pedicel;
            let a = self.attached.get_mut(&f).expect("listed");
            let load = a.load(&p, &pose, h);
            if let Some(mode) = load.breaks(&a.thresholds) {
                self.attached.remove(&f);
                self.detached(world, f, Some((mode, load)));
            } else {
                for s in 0..2 {
                    if self.grippers[s].held == Some(f) {
                        self.loads[s] = Some(load);
                    }
                }
            }
        }
        for s in 0..2 {
            if let Some(f) = self.grippers[s].held {
                if grip_forces[s] > self.params.damage.bruise_grip_force {
                    self.damage.grip_bruised.insert(f);
                    self.damage.peak_grip = self.damage.peak_grip.max(grip_forces[s]);
                }
            }
        }
    }

    /// Kinematic targets of held and placed fruit for hands at `hands` and the box frame at
    /// `box_pose` (map frame); only those that move.
    pub fn fruit_moves(
        &self,
        world: &SceneWorld,
        hands: &[RPose; 2],
        box_pose: &RPose,
        out: &mut Vec<(RigidBodyHandle, Pose)>,
    ) {
        for (&f, state) in &self.fruit {
            let target = match state {
                FruitState::Held { leader } => hands[*leader as usize].mul(&self.grippers[*leader as usize].grip),
                FruitState::Placed { in_box } => box_pose.mul(in_box),
                _ => continue,
            };
            let body = world.fruit[f].body;
            let pose = to_rapier(&target);
            if *world.bodies[body].position() != pose {
                out.push((body, pose));
            }
        }
    }

    /// Bodies of carried and placed fruit (kinematic things a falling fruit may land on).
    pub fn kinematic_fruit(&self, world: &SceneWorld, out: &mut Vec<RigidBodyHandle>) {
        out.clear();
        for (&f, state) in &self.fruit {
            if matches!(state, FruitState::Held { .. } | FruitState::Placed { .. }) {
                out.push(world.fruit[f].body);
            }
        }
    }

    /// Settles falling fruit after the physics step of `h` seconds: floor -> dropped; at rest
    /// -> placed (inside the box) or dropped. `box_vel` is the box's velocity [m/s].
    pub fn settle(
        &mut self,
        world: &mut SceneWorld,
        interior: &BoxInterior,
        box_pose: &RPose,
        box_vel: [f64; 3],
        h: f64,
    ) {
        let falling: Vec<(usize, f64, f64)> = self
            .fruit
            .iter()
            .filter_map(|(&f, s)| match *s {
                FruitState::Falling { rest, airborne } => Some((f, rest, airborne)),
                _ => None,
            })
            .collect();
        for (f, mut rest, mut airborne) in falling {
            airborne += h;
            let body = world.fruit[f].body;
            let pose = from_rapier(world.bodies[body].position());
            let p = pose.trans;
            if p[2] - world.fruit[f].radius <= FLOOR_EPS || p[2] < -1.0 {
                self.landed(f);
                self.drop_fruit(world, f);
                continue;
            }
            let v = world.bodies[body].linvel();
            let speed = norm([v.x as f64, v.y as f64, v.z as f64]);
            let fastest = self.fall_speed.entry(f).or_insert(0.0);
            *fastest = fastest.max(speed);
            let rel = sub([v.x as f64, v.y as f64, v.z as f64], box_vel);
            rest = if norm(rel) < REST_SPEED { rest + h } else { 0.0 };
            if rest + 1e-9 >= REST_TIME || airborne >= MAX_FALL_TIME {
                self.landed(f);
                let in_box = box_pose.inverse().mul(&pose);
                if interior.contains(in_box.trans) {
                    world.bodies[body].set_body_type(RigidBodyType::KinematicPositionBased, true);
                    world.bodies[body].enable_ccd(false);
                    self.fruit.insert(f, FruitState::Placed { in_box });
                    self.placed += 1;
                    self.last_placed = Some(f);
                } else {
                    self.drop_fruit(world, f);
                }
            } else {
                self.fruit.insert(f, FruitState::Falling { rest, airborne });
            }
        }
    }

    /// A falling fruit came to rest: bruised if it ever went faster than the impact threshold
    /// (the speed it hit with).
    fn landed(&mut self, f: usize) {
        let v = self.fall_speed.remove(&f).unwrap_or(0.0);
        if v > self.params.damage.bruise_impact_speed {
            self.damage.impact_bruised.insert(f);
            self.damage.peak_impact = self.damage.peak_impact.max(v);
        }
    }

    fn drop_fruit(&mut self, world: &mut SceneWorld, f: usize) {
        let b = &mut world.bodies[world.fruit[f].body];
        b.set_body_type(RigidBodyType::Fixed, true);
        b.enable_ccd(false);
        self.fruit.insert(f, FruitState::Dropped);
        self.dropped += 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_fruit_nearly_as_wide_as_the_open_gripper_is_let_go_when_it_is_open_all_the_way() {
        // Regression (10 m row segment, fruit 97 of 179, 77 mm): never let go before.
        assert!(!releases(0.079, 0.077, 0.005, 0.08));
        assert!(releases(0.08, 0.077, 0.005, 0.08));
        // A fruit wider than the open gripper stays jammed; a small one goes at the margin.
        assert!(!releases(0.08, 0.081, 0.005, 0.08));
        assert!(releases(0.066, 0.06, 0.005, 0.08) && !releases(0.064, 0.06, 0.005, 0.08));
    }

    #[test]
    fn a_fruit_held_by_both_grippers_is_carried_once() {
        let mut h = Harvest::new(HarvestParams::new(0.0, 0.0), [0.08; 2], [RPose::IDENTITY; 2]);
        assert_eq!(h.carried().count(), 0);
        h.grippers[1].held = Some(4);
        assert_eq!(h.carried().collect::<Vec<_>>(), [4]);
        h.grippers[0].held = Some(4);
        assert_eq!(h.carried().collect::<Vec<_>>(), [4], "a handover");
        h.grippers[0].held = Some(2);
        assert_eq!(h.carried().collect::<Vec<_>>(), [2, 4]);
    }
}
