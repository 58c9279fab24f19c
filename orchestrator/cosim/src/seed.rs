//! Per-component seeds: one master seed for a run, an independent seed for every component.

/// The seed of one component: the master seed mixed with the component's name (FNV-1a), so
/// that components draw independent noise and adding a component changes no one else's.
pub fn component_seed(master: u64, component: &str) -> i32 {
    let mut h = 0xcbf2_9ce4_8422_2325u64 ^ master.wrapping_mul(0x9E37_79B9_7F4A_7C15);
    for b in component.bytes() {
        h ^= b as u64;
        h = h.wrapping_mul(0x0100_0000_01b3);
    }
    (h >> 33) as i32
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn component_seeds_differ_by_name_and_master_seed() {
        assert_ne!(component_seed(1, "chassis"), component_seed(1, "lift"));
        assert_ne!(component_seed(1, "chassis"), component_seed(2, "chassis"));
        assert_eq!(component_seed(7, "chassis"), component_seed(7, "chassis"));
    }
}
