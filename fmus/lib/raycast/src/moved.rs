//! A sensor's scene when some objects are away from where the greenhouse grew them (leaves a
//! robot part pushed aside, picked fruit; the world FMU's `moved_objects`).
//!
//! The scene's tree is built once and shared by every sensor of a process, and rebuilding
//! it per frame would cost more than the frame. So a moved object stays in the tree with a
//! primitive that no ray can meet, in a copy of the scene made when the first object moves,
//! and is cast at its new placement among the frame's moving objects (the robot's links),
//! with its own id and kind. The copy is patched object by object as the list changes; an
//! object back at rest gets its primitive back. Answers stay exactly those of a scene built
//! with the objects at their new placements (the tests compare with brute force).

use crate::cast_scene::CastScene;
use crate::primitives::Prim;
use agrisim_scene::{Object, Placement};
use std::collections::BTreeMap;

/// The scene as grown, or a patched copy of it (see the module documentation).
#[derive(Clone, Debug, Default)]
pub struct MovedScene {
    own: Option<Box<Own>>,
}

#[derive(Clone, Debug)]
struct Own {
    scene: CastScene,
    /// Index of each object's primitive in the tree's leaf order, by object id.
    slot: Vec<u32>,
    /// The moved objects and their placements, as applied to `scene`.
    applied: BTreeMap<u32, Placement>,
}

impl Own {
    fn of(base: &CastScene) -> Own {
        let mut slot = vec![u32::MAX; base.object_count()];
        for (k, &id) in base.caster.ids.iter().enumerate() {
            if let Some(s) = slot.get_mut(id as usize) {
                *s = k as u32;
            }
        }
        Own { scene: base.clone(), slot, applied: BTreeMap::new() }
    }

    fn place(&mut self, id: u32, placement: Placement) {
        if let Some(&k) = self.slot.get(id as usize).filter(|&&k| k != u32::MAX) {
            self.scene.caster.prims[k as usize] = Prim::NEVER;
            self.scene.geometry[id as usize].1 = placement;
        }
    }

    fn restore(&mut self, base: &CastScene, id: u32) {
        if let Some(&k) = self.slot.get(id as usize).filter(|&&k| k != u32::MAX) {
            self.scene.caster.prims[k as usize] = base.caster.prims[k as usize];
            self.scene.geometry[id as usize] = base.geometry[id as usize];
        }
    }
}

impl MovedScene {
    /// Brings the view to `moves` (object id, placement; every other object as grown). Ids
    /// beyond `base` are ignored. `base` must be the scene of every earlier call.
    pub fn update(&mut self, base: &CastScene, moves: &[(u32, Placement)]) {
        let want: BTreeMap<u32, Placement> =
            moves.iter().copied().filter(|&(id, _)| (id as usize) < base.object_count()).collect();
        if want.is_empty() {
            self.own = None;
            return;
        }
        let own = self.own.get_or_insert_with(|| Box::new(Own::of(base)));
        let gone: Vec<u32> = own.applied.keys().copied().filter(|id| !want.contains_key(id)).collect();
        for id in gone {
            own.restore(base, id);
        }
        for (&id, &placement) in &want {
            if own.applied.get(&id) != Some(&placement) {
                own.place(id, placement);
            }
        }
        own.applied = want;
    }

    /// The scene to cast at: `base` while nothing moved, else the patched copy.
    pub fn scene<'a>(&'a self, base: &'a CastScene) -> &'a CastScene {
        self.own.as_ref().map_or(base, |o| &o.scene)
    }

    /// Number of moved objects.
    pub fn len(&self) -> usize {
        self.own.as_ref().map_or(0, |o| o.applied.len())
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The moved objects at their placements (scene ids and kinds), to cast among the
    /// frame's moving objects.
    pub fn objects(&self) -> Vec<Object> {
        let Some(own) = &self.own else { return Vec::new() };
        own.applied
            .iter()
            .map(|(&id, &placement)| Object {
                id,
                name: String::new(),
                kind: own.scene.kind(id),
                shape: own.scene.geometry[id as usize].0,
                placement,
            })
            .collect()
    }
}
