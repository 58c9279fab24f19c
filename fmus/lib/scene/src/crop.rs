//! Crop presets: `crop = "loose_round" | "truss" | "cherry"` in a scenario's `[greenhouse]`
//! sets the crop's fields (fruit per truss, fruit size, leaves); any of those fields the
//! `[greenhouse]` table gives itself overrides the preset's value. Applied when a
//! `[greenhouse]` table is parsed ([`crate::GreenhouseConfig::from_toml_str`]), so every
//! consumer of the same TOML text (world FMU, LiDAR, camera, judge) gets the same crop.
//!
//! Sources, per value below. Fruit radii come from fresh masses through a sphere of density
//! 1 g/cm^3 (tomato fruit are close to it): r = (3 m / 4 pi)^(1/3), so 100 g -> 28.8 mm.
//! "Heuvelink 2018" is E. Heuvelink (ed.), Tomatoes, 2nd ed., Crop Production Science in
//! Horticulture 27, CABI 2018 (ch. 3, growth and development: the sympodial stem forms a
//! truss after every three leaves; high-wire crops are de-leafed below the lowest ripening
//! truss). Values marked "estimate" are our choice within what those sources allow, not a
//! figure read from them.

/// The preset names, in documentation order.
pub const CROPS: [&str; 3] = ["loose_round", "truss", "cherry"];

/// The fields a preset sets (the `[greenhouse]` keys it gives defaults for).
pub const CROP_FIELDS: [&str; 7] = [
    "trusses_per_plant",
    "fruit_per_truss",
    "fruit_radius",
    "fruit_radius_spread",
    "fruit_radius_limits",
    "leaf_density",
    "leaf_size",
];

/// One crop's values of [`CROP_FIELDS`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Crop {
    pub trusses_per_plant: usize,
    pub fruit_per_truss: usize,
    pub fruit_radius: f64,
    pub fruit_radius_spread: f64,
    pub fruit_radius_limits: [f64; 2],
    pub leaf_density: usize,
    pub leaf_size: [f64; 2],
}

/// Loose round tomatoes, harvested fruit by fruit: today's default greenhouse, exactly (the
/// values are [`GreenhouseConfig::default`]'s, so the default scene is unchanged).
pub const LOOSE_ROUND: Crop = Crop {
    // Trusses within the arms' fruit band (1.3 m of stem; a truss every ~0.3 m of a high-wire
    // stem: 3 leaves of ~0.1 m internodes, Heuvelink 2018 ch. 3). Estimate.
    trusses_per_plant: 4,
    // Loose round crops are pruned to 4-6 fruit per truss (growers' truss pruning). Estimate.
    fruit_per_truss: 5,
    // 60 mm diameter: the EU marketing standard's size code 57-67 mm for round tomatoes
    // (Commission Implementing Regulation (EU) No 543/2011, Annex I Part B Part 10); ~110 g.
    fruit_radius: 0.03,
    // 10 % (1 sigma) of the radius, clamped to 0.6-1.4 x: estimate.
    fruit_radius_spread: 0.1,
    fruit_radius_limits: [0.6, 1.4],
    // Leaves left in the fruit zone after de-leafing (Heuvelink 2018 ch. 3). Estimate.
    leaf_density: 6,
    // Leaf blob 0.3 x 0.2 m, the part of a compound leaf that occludes fruit. Estimate.
    leaf_size: [0.3, 0.2],
};

/// Truss (vine) tomatoes, harvested as whole trusses: more, slightly smaller fruit per truss
/// and a denser canopy.
pub const TRUSS: Crop = Crop {
    // As loose round: same high-wire stem and fruit band. Estimate.
    trusses_per_plant: 4,
    // Truss cultivars carry 6-8 fruit per truss (the figure; growers prune trusses to
    // 6-8 for uniform ripening along the truss): the middle, 7.
    fruit_per_truss: 7,
    // 80-120 g per fruit (the figure for truss cultivars) -> radius 26.7-30.6 mm by
    // the sphere of density 1: 100 g, 28.8 mm.
    fruit_radius: 0.0288,
    // 80-120 g is +-20 % in mass, +-6.7 % in radius: 1 sigma 5 %, clamped to the 80-120 g
    // radii (0.927-1.063 x).
    fruit_radius_spread: 0.05,
    fruit_radius_limits: [0.927, 1.063],
    // Dense leaves: about three leaves per truss (Heuvelink 2018 ch. 3), 4 trusses -> up to
    // 12; 10 left after de-leafing of the lowest ones. Estimate.
    leaf_density: 10,
    // Mature tomato leaves are 0.3-0.5 m long (Heuvelink 2018 ch. 3; SEINet "Solanum
    // lycopersicum": leaves to 40 cm). The occluding blob: 0.4 x 0.25 m. Estimate.
    leaf_size: [0.4, 0.25],
};

/// Cherry tomatoes: many small fruit on long trusses.
pub const CHERRY: Crop = Crop {
    // As loose round. Estimate.
    trusses_per_plant: 4,
    // 12-20 fruit per truss (the figure for cherry cultivars): the middle, 16.
    fruit_per_truss: 16,
    // 25-35 mm diameter (the figure; 10-25 g fruit: a sphere of density 1 weighs
    // 8-22 g over that range): radius 15 mm, the middle.
    fruit_radius: 0.015,
    // 1 sigma 7 %, clamped to exactly 25-35 mm diameter (12.5-17.5 mm radius).
    fruit_radius_spread: 0.07,
    fruit_radius_limits: [0.0125 / 0.015, 0.0175 / 0.015],
    // As loose round (cherry crops are de-leafed the same way). Estimate.
    leaf_density: 6,
    // Cherry cultivars have somewhat smaller leaves. Estimate.
    leaf_size: [0.3, 0.2],
};

/// The preset called `name`, if there is one.
pub fn preset(name: &str) -> Option<Crop> {
    match name {
        "loose_round" => Some(LOOSE_ROUND),
        "truss" => Some(TRUSS),
        "cherry" => Some(CHERRY),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_named_crop_has_a_preset() {
        for c in CROPS {
            assert!(preset(c).is_some(), "{c}");
        }
        assert_eq!(preset("beefsteak"), None);
    }
}
