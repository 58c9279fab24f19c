//! What every perception trial of a scene shares: the layout (aisles for the poses) and the
//! fruit with their ground truth (radius, ripeness), in the order of the world's /fruits.

use agrisim_error::{err, Result};
use agrisim_scene::{Kind, Shape};
use agrisim_session::Scenario;

#[derive(Clone, Debug)]
pub struct TruthFruit {
    /// Scene object id (the camera's label value is id + 1).
    pub id: u32,
    pub center: [f64; 3],
    pub radius: f64,
    pub stage: u8,
}

pub struct PerceptionSetup {
    pub layout: agrisim_scene::Layout,
    pub fruit: Vec<TruthFruit>,
    /// Scene object id -> index in `fruit` (None for other objects).
    pub by_id: Vec<Option<u32>>,
    /// Scene object id -> its kind (what a false detection sits on).
    pub kinds: Vec<Kind>,
}

impl PerceptionSetup {
    pub fn new(s: &Scenario) -> Result<PerceptionSetup> {
        let g = agrisim_session::scene::generate_scene(s)?;
        let mut fruit = vec![];
        let mut by_id = vec![None; g.objects.len()];
        let mut kinds = vec![Kind::Obstacle; g.objects.len()];
        for o in &g.objects {
            if let Some(k) = kinds.get_mut(o.id as usize) {
                *k = o.kind;
            }
            if let (Kind::Fruit { ripeness }, Shape::Sphere { radius }) = (o.kind, o.shape) {
                by_id[o.id as usize] = Some(fruit.len() as u32);
                fruit.push(TruthFruit { id: o.id, center: o.placement.translation, radius, stage: ripeness });
            }
        }
        if g.layout.aisles.is_empty() || fruit.is_empty() {
            return Err(err!("scenario {}: no aisle or no fruit to look at", s.path.display()));
        }
        Ok(PerceptionSetup { layout: g.layout, fruit, by_id, kinds })
    }
}

impl PerceptionSetup {
    /// Checks that the running world's fruit (its /fruits, in fruit order) are this setup's:
    /// the labels of the camera are scene object ids, which name this setup's fruit only if
    /// the FMUs generated the same scene as the orchestrator. A world built by another scene
    /// generator (FMUs packed from other sources than this executable) may have as many fruit
    /// elsewhere, and judging it by this setup's ids would pair each label with some other
    /// fruit.
    pub fn check_world(&self, centers: &[[f64; 3]]) -> Result<()> {
        if centers.len() != self.fruit.len() {
            return Err(err!(
                "the world has {} fruit, the orchestrator's scene {}: FMUs and this executable generate different scenes (re-pack the FMUs: agrisim fmu pack)",
                centers.len(),
                self.fruit.len()
            ));
        }
        let off = self
            .fruit
            .iter()
            .zip(centers)
            .filter(|(f, c)| {
                (0..3).map(|k| (f.center[k] - c[k]).powi(2)).sum::<f64>() > WORLD_TOLERANCE * WORLD_TOLERANCE
            })
            .count();
        if off * 100 > self.fruit.len() {
            return Err(err!(
                "{off} of {} fruit of the world lie over {} mm from the orchestrator's scene: FMUs and this executable generate different scenes (re-pack the FMUs: agrisim fmu pack)",
                self.fruit.len(),
                1000.0 * WORLD_TOLERANCE
            ));
        }
        Ok(())
    }
}

/// Largest distance of a world fruit from the scene's [m] (fixed bodies: only a touch moves them).
const WORLD_TOLERANCE: f64 = 0.002;
