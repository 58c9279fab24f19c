//! The whole-row harvest: one [`HarvestNode`] taken through a list of fruit, one after the
//! other, moving the base between picks. After each fruit, picked or not, the node lets go
//! of anything it holds and brings both arms home before it selects the next
//! ([`Stage::Recover`]). Every fruit's stages and outcome go to `/harvest/status` with its
//! `target_id`, as in the single-fruit task, so one judge reads both.
//!
//! The node is told the fruit to pick, in order (the world's fruit-list indices, as the
//! paper hands over a target); their poses it learns one at a time from `/target_fruit`.

use super::node::HarvestNode;
use super::stage::Stage;
use agrisim_bus::{Bus, Node};
use agrisim_error::Result;

pub struct RowNode {
    targets: Vec<usize>,
    /// Index into `targets` of the fruit being harvested.
    current: usize,
    inner: HarvestNode,
}

impl RowNode {
    /// Harvests `targets` (fruit-list indices) in this order; `seed` drives the planners.
    pub fn new(targets: Vec<usize>, seed: u64) -> RowNode {
        let first = targets.first().copied().unwrap_or(0);
        RowNode { targets, current: 0, inner: HarvestNode::new(first, seed) }
    }
}

impl Node for RowNode {
    fn name(&self) -> &str {
        "harvest"
    }

    fn step(&mut self, t_ns: i64, bus: &mut Bus) -> Result<()> {
        if self.targets.is_empty() {
            return Ok(());
        }
        if matches!(self.inner.stage(), Stage::Done | Stage::Failed) && self.current + 1 < self.targets.len() {
            self.current += 1;
            self.inner.next_target(self.targets[self.current], t_ns, bus);
        }
        self.inner.step(t_ns, bus)
    }
}
