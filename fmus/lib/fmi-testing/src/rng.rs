/// The harness' draws, on the workspace's generator (`agrisim_math::Rng`, noise flavour):
/// reproducible per seed; indices are `usize` (`below(0)` is 0), plus percent chances and
/// special float and integer values.
pub(crate) struct FuzzRng(agrisim_math::Rng);

impl FuzzRng {
    pub fn new(seed: u64) -> FuzzRng {
        FuzzRng(agrisim_math::Rng::new(seed))
    }
    pub fn next_u64(&mut self) -> u64 {
        self.0.next_u64()
    }
    pub fn below(&mut self, n: usize) -> usize {
        self.0.below(n.max(1) as u64) as usize
    }
    pub fn chance(&mut self, percent: u64) -> bool {
        self.next_u64() % 100 < percent
    }
    pub(crate) fn pick<T: Copy>(&mut self, xs: &[T]) -> T {
        xs[self.below(xs.len())]
    }
    pub(crate) fn f64(&mut self) -> f64 {
        match self.below(10) {
            0 => f64::NAN,
            1 => self.pick(&[f64::INFINITY, f64::NEG_INFINITY, 1e300, -1e300]),
            2 => 0.0,
            _ => (self.next_u64() % 2001) as f64 / 100.0 - 10.0,
        }
    }
    pub(crate) fn int(&mut self) -> i64 {
        match self.below(4) {
            0 => self.next_u64() as i64,
            _ => self.below(7) as i64 - 2,
        }
    }
}
