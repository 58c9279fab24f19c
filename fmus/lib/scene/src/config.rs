//! `[greenhouse]` of a scenario: everything that shapes the scene. Defaults are the paper's
//! setup (Agri-Sim, Table "Principal experimental configuration": a 70 x 55 x 10 m greenhouse,
//! 6 rows enabled, 2 m aisles); what the paper does not state (row length, plant and fruit
//! sizes) is taken from common high-wire tomato practice and said so at the field.
//!
//! Unknown keys are errors, and every error names the key, so a typo never silently falls
//! back to a default.

use crate::family::FamilyConfig;
use serde::Deserialize;

/// A box obstacle standing on the floor, placed by the scenario.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ObstacleConfig {
    /// Centre of the footprint in the map frame [m].
    pub x: f64,
    pub y: f64,
    /// Footprint along x and y [m].
    pub size_x: f64,
    pub size_y: f64,
    /// Height above the floor [m].
    #[serde(default = "default_obstacle_height")]
    pub height: f64,
}

fn default_obstacle_height() -> f64 {
    1.0
}

/// The greenhouse configuration (the keys of a scenario's `[greenhouse]` table).
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct GreenhouseConfig {
    /// Scene seed: fed to [`crate::generate`] by callers that do not override it.
    pub seed: u64,

    // --- Hall -------------------------------------------------------------------------------
    /// Inner length along x (along the rows) [m]. Paper: 70 m.
    pub length: f64,
    /// Inner width along y (across the rows) [m]. Paper: 55 m.
    pub width: f64,
    /// Height of the roof [m]. Paper: 10 m.
    pub height: f64,
    /// Generate the perimeter walls, the roof and the floor slab.
    pub walls: bool,

    // --- Rows and aisles ----------------------------------------------------------------------
    /// Total plant rows (geometry). The paper's complete layout has 160.
    pub rows: usize,
    /// Rows that take part in experiments (aisles between them are navigation goals). Paper: 6.
    pub active_rows: usize,
    /// Index of the first active row; the active rows are contiguous.
    pub first_active_row: usize,
    /// Free space between the foliage envelopes of two neighbouring rows [m]. Paper: 2 m.
    pub aisle_width: f64,
    /// Width of a row's foliage envelope (all plant parts stay inside it) [m].
    pub row_width: f64,
    /// Length of a plant row [m] (not in the paper; chosen so a nav trial crosses it in ~1 min).
    pub row_length: f64,
    /// Headland path between the front wall (x = 0) and the row starts [m].
    pub headland: f64,

    // --- Crop ---------------------------------------------------------------------------------
    /// Crop preset (`crate::crop`): "loose_round" (the default), "truss" or "cherry". Sets the
    /// crop fields (trusses_per_plant, fruit_per_truss, fruit_radius, fruit_radius_spread,
    /// fruit_radius_limits, leaf_density, leaf_size) that the table does not give itself.
    /// Applied by [`GreenhouseConfig::from_toml_str`].
    pub crop: String,
    /// `[greenhouse.family]`: ranges the crop and layout are drawn from, per scene seed
    /// (`crate::family`). Drawn by [`GreenhouseConfig::from_toml_str`].
    pub family: Option<FamilyConfig>,

    // --- Plants -------------------------------------------------------------------------------
    /// Distance between plants along a row [m] (2.5 plants/m^2-type spacing: 0.5 m).
    pub plant_spacing: f64,
    /// Stem height [m].
    pub plant_height: f64,
    pub stem_radius: f64,
    pub trusses_per_plant: usize,
    pub fruit_per_truss: usize,
    /// Fruit radius [m] (truss tomatoes: 50-70 mm diameter).
    pub fruit_radius: f64,
    /// Relative spread of fruit radius (1 sigma, fraction of `fruit_radius`).
    pub fruit_radius_spread: f64,
    /// Every fruit's radius stays within these factors of `fruit_radius`.
    pub fruit_radius_limits: [f64; 2],
    /// Fruit centre heights stay within this band [m] (reachable by the arms).
    pub fruit_height: [f64; 2],
    /// Weights of the six USDA ripeness stages: green, breakers, turning, pink, light red, red.
    pub ripeness: [f64; 6],
    /// Leaf blobs per plant (occlusion).
    pub leaf_density: usize,
    /// Leaf blob size: length, width [m] (flat boxes 1 cm thick).
    pub leaf_size: [f64; 2],

    // --- Structure ----------------------------------------------------------------------------
    /// Overhead gutters along every row.
    pub gutters: bool,
    pub gutter_height: f64,
    /// Steel posts in the row line.
    pub posts: bool,
    pub post_spacing: f64,
    pub post_radius: f64,
    /// Two heating pipes on the floor under each row.
    pub heating_pipes: bool,
    pub pipe_radius: f64,
    /// Lateral offset of each pipe from the row line [m] (inside the row envelope).
    pub pipe_offset: f64,

    // --- Obstacles ----------------------------------------------------------------------------
    /// Placed obstacles (`[[greenhouse.obstacles]]`).
    pub obstacles: Vec<ObstacleConfig>,
    /// Number of seeded random box obstacles in the aisles of the active rows.
    pub random_obstacles: usize,
    /// Footprint side range of random obstacles [m].
    pub random_obstacle_size: [f64; 2],
    /// Height range of random obstacles [m].
    pub random_obstacle_height: [f64; 2],
    /// Random obstacles always leave at least this much free width in an aisle [m]
    /// (robot 0.9 m wide + clearance).
    pub min_passage: f64,
    /// Aisles (indices into `Layout::aisles`) closed by a wall across their middle.
    pub block_aisles: Vec<usize>,
}

impl Default for GreenhouseConfig {
    fn default() -> Self {
        GreenhouseConfig {
            seed: 1,
            crop: "loose_round".into(),
            family: None,
            length: 70.0,
            width: 55.0,
            height: 10.0,
            walls: true,
            rows: 6,
            active_rows: 6,
            first_active_row: 0,
            aisle_width: 2.0,
            row_width: 0.6,
            row_length: 30.0,
            headland: 4.0,
            plant_spacing: 0.5,
            plant_height: 2.2,
            stem_radius: 0.012,
            trusses_per_plant: 4,
            fruit_per_truss: 5,
            fruit_radius: 0.03,
            fruit_radius_spread: 0.1,
            fruit_radius_limits: [0.6, 1.4],
            fruit_height: [0.5, 1.8],
            ripeness: [0.25, 0.1, 0.1, 0.1, 0.15, 0.3],
            leaf_density: 6,
            leaf_size: [0.3, 0.2],
            gutters: true,
            gutter_height: 3.0,
            posts: true,
            post_spacing: 4.0,
            post_radius: 0.04,
            heating_pipes: true,
            pipe_radius: 0.0255,
            pipe_offset: 0.2,
            obstacles: Vec::new(),
            random_obstacles: 0,
            random_obstacle_size: [0.3, 0.6],
            random_obstacle_height: [0.4, 1.2],
            min_passage: 1.2,
            block_aisles: Vec::new(),
        }
    }
}

impl GreenhouseConfig {
    /// Parses the keys of a `[greenhouse]` table ("" gives the default), applies its crop
    /// preset (`crop`: to the crop fields the table does not give) and its family draw
    /// (`[greenhouse.family]`, for the table's `seed`), and validates the result. Errors name
    /// the offending key, e.g. `greenhouse.rows: ...`.
    pub fn from_toml_str(s: &str) -> Result<GreenhouseConfig, String> {
        let mut cfg: GreenhouseConfig = toml::from_str(s).map_err(|e| describe_toml_error(s, &e))?;
        let table: toml::Table = toml::from_str(s).map_err(|e| describe_toml_error(s, &e))?;
        let explicit = |k: &str| table.contains_key(k);
        let crop = crate::crop::preset(&cfg.crop).ok_or_else(|| {
            format!("greenhouse.crop: unknown crop {:?}; known: {}", cfg.crop, crate::crop::CROPS.join(", "))
        })?;
        cfg.apply_crop(&crop, &explicit);
        if let Some(family) = cfg.family.clone() {
            let draw = family.draw(cfg.seed, &explicit)?;
            cfg.apply_draw(&draw);
        }
        cfg.validate()?;
        Ok(cfg)
    }

    /// Sets every crop field for which `explicit(key)` is false (the scenario did not give
    /// the key itself) to the preset's value.
    fn apply_crop(&mut self, c: &crate::crop::Crop, explicit: &dyn Fn(&str) -> bool) {
        let set = |k: &str| !explicit(k);
        if set("trusses_per_plant") {
            self.trusses_per_plant = c.trusses_per_plant;
        }
        if set("fruit_per_truss") {
            self.fruit_per_truss = c.fruit_per_truss;
        }
        if set("fruit_radius") {
            self.fruit_radius = c.fruit_radius;
        }
        if set("fruit_radius_spread") {
            self.fruit_radius_spread = c.fruit_radius_spread;
        }
        if set("fruit_radius_limits") {
            self.fruit_radius_limits = c.fruit_radius_limits;
        }
        if set("leaf_density") {
            self.leaf_density = c.leaf_density;
        }
        if set("leaf_size") {
            self.leaf_size = c.leaf_size;
        }
    }

    /// Sets the values a family drew.
    fn apply_draw(&mut self, d: &crate::family::FamilyDraw) {
        self.aisle_width = d.aisle_width.unwrap_or(self.aisle_width);
        self.fruit_per_truss = d.fruit_per_truss.unwrap_or(self.fruit_per_truss);
        self.leaf_density = d.leaf_density.unwrap_or(self.leaf_density);
        self.fruit_radius = d.fruit_radius.unwrap_or(self.fruit_radius);
        self.fruit_height[0] = d.fruit_height_low.unwrap_or(self.fruit_height[0]);
        self.fruit_height[1] = d.fruit_height_high.unwrap_or(self.fruit_height[1]);
        self.trusses_per_plant = d.trusses_per_plant.unwrap_or(self.trusses_per_plant);
        self.plant_spacing = d.plant_spacing.unwrap_or(self.plant_spacing);
    }

    /// Distance between neighbouring row lines [m].
    pub fn row_pitch(&self) -> f64 {
        self.row_width + self.aisle_width
    }

    /// Checks ranges and that everything fits; the error names the key.
    pub fn validate(&self) -> Result<(), String> {
        let err = |key: &str, msg: String| Err(format!("greenhouse.{key}: {msg}"));
        let positive = [
            ("length", self.length),
            ("width", self.width),
            ("height", self.height),
            ("aisle_width", self.aisle_width),
            ("row_width", self.row_width),
            ("row_length", self.row_length),
            ("plant_spacing", self.plant_spacing),
            ("plant_height", self.plant_height),
            ("stem_radius", self.stem_radius),
            ("fruit_radius", self.fruit_radius),
            ("gutter_height", self.gutter_height),
            ("post_spacing", self.post_spacing),
            ("post_radius", self.post_radius),
            ("pipe_radius", self.pipe_radius),
        ];
        for (k, v) in positive {
            if !(v.is_finite() && v > 0.0) {
                return err(k, format!("must be a positive number, got {v}"));
            }
        }
        let non_negative = [
            ("headland", self.headland),
            ("fruit_radius_spread", self.fruit_radius_spread),
            ("min_passage", self.min_passage),
            ("pipe_offset", self.pipe_offset),
        ];
        for (k, v) in non_negative {
            if !(v.is_finite() && v >= 0.0) {
                return err(k, format!("must be >= 0, got {v}"));
            }
        }
        for (k, [a, b]) in [
            ("fruit_height", self.fruit_height),
            ("random_obstacle_size", self.random_obstacle_size),
            ("random_obstacle_height", self.random_obstacle_height),
        ] {
            if !(a.is_finite() && b.is_finite() && a > 0.0 && a <= b) {
                return err(k, format!("must be [low, high] with 0 < low <= high, got [{a}, {b}]"));
            }
        }
        if crate::crop::preset(&self.crop).is_none() {
            return err("crop", format!("unknown crop {:?}; known: {}", self.crop, crate::crop::CROPS.join(", ")));
        }
        if let Some(f) = &self.family {
            f.validate()?;
        }
        let [lo, hi] = self.fruit_radius_limits;
        if !(lo.is_finite() && hi.is_finite() && lo > 0.0 && lo <= 1.0 && hi >= 1.0) {
            return err(
                "fruit_radius_limits",
                format!("must be [low, high] with 0 < low <= 1 <= high, got [{lo}, {hi}]"),
            );
        }
        if !self.leaf_size.iter().all(|v| v.is_finite() && *v > 0.0) {
            return err("leaf_size", format!("[length, width] must be positive, got {:?}", self.leaf_size));
        }
        if self.rows == 0 {
            return err("rows", "must be at least 1".into());
        }
        if self.active_rows > self.rows {
            return err("active_rows", format!("{} exceeds rows = {}", self.active_rows, self.rows));
        }
        if self.first_active_row + self.active_rows > self.rows {
            return err(
                "first_active_row",
                format!("{} + active_rows {} exceeds rows = {}", self.first_active_row, self.active_rows, self.rows),
            );
        }
        if self.ripeness.iter().any(|w| !(w.is_finite() && *w >= 0.0)) || self.ripeness.iter().sum::<f64>() <= 0.0 {
            return err("ripeness", "six non-negative weights, not all zero".into());
        }
        if self.fruit_height[1] > self.plant_height {
            return err(
                "fruit_height",
                format!("top {} is above plant_height {}", self.fruit_height[1], self.plant_height),
            );
        }
        let need_w = self.rows as f64 * self.row_pitch();
        if need_w > self.width {
            return err(
                "width",
                format!(
                    "{} m is too narrow for rows = {} at pitch {} m (row_width + aisle_width); need at least {need_w} m",
                    self.width,
                    self.rows,
                    self.row_pitch()
                ),
            );
        }
        if self.headland + self.row_length > self.length {
            return err(
                "row_length",
                format!("headland {} + row_length {} exceeds length {}", self.headland, self.row_length, self.length),
            );
        }
        if self.pipe_offset + self.pipe_radius > 0.5 * self.row_width {
            return err("pipe_offset", "heating pipes must lie inside the row envelope (row_width / 2)".into());
        }
        if self.gutters && self.gutter_height >= self.height {
            return err("gutter_height", format!("must be below the roof (height = {})", self.height));
        }
        if self.random_obstacles > 0 && self.random_obstacle_size[1] > self.aisle_width - self.min_passage {
            return err(
                "random_obstacle_size",
                format!(
                    "largest side {} leaves less than min_passage {} of a {} m aisle",
                    self.random_obstacle_size[1], self.min_passage, self.aisle_width
                ),
            );
        }
        let aisles = self.active_rows.saturating_sub(1);
        for &a in &self.block_aisles {
            if a >= aisles {
                return err("block_aisles", format!("aisle {a} does not exist (there are {aisles} aisles)"));
            }
        }
        for (i, o) in self.obstacles.iter().enumerate() {
            let ok = [o.x, o.y].iter().all(|v| v.is_finite())
                && [o.size_x, o.size_y, o.height].iter().all(|v| v.is_finite() && *v > 0.0);
            if !ok {
                return err(&format!("obstacles[{i}]"), "x, y finite; size_x, size_y, height positive".into());
            }
        }
        Ok(())
    }
}

/// Turns a toml/serde error into one line that names the key (toml reports a byte span; the
/// key is read from the source line it points at, with the enclosing `[[table]]` if any).
fn describe_toml_error(src: &str, e: &toml::de::Error) -> String {
    let msg = e.message().trim().to_string();
    let Some(span) = e.span() else { return format!("greenhouse: {msg}") };
    let start = span.start.min(src.len());
    let line_start = src[..start].rfind('\n').map_or(0, |i| i + 1);
    let line_end = src[start..].find('\n').map_or(src.len(), |i| start + i);
    let line = &src[line_start..line_end];
    let line_no = src[..line_start].matches('\n').count() + 1;
    // The table the line belongs to: the last header before it.
    let mut table = String::new();
    let mut count = std::collections::BTreeMap::<String, usize>::new();
    for l in src[..line_end].lines() {
        let t = l.trim();
        if let Some(h) = t.strip_prefix("[[").and_then(|r| r.split("]]").next()) {
            let h = h.trim().to_string();
            let n = count.entry(h.clone()).or_insert(0);
            table = format!("{h}[{n}]");
            *n += 1;
        } else if let Some(h) = t.strip_prefix('[').and_then(|r| r.split(']').next()) {
            table = h.trim().to_string();
        }
    }
    let key = match line.split_once('=') {
        Some((k, _)) if !line.trim_start().starts_with('[') => k.trim().trim_matches('"').to_string(),
        _ => String::new(),
    };
    // `unknown field` messages already name the key; still prefix the path for context.
    let path = match (table.is_empty(), key.is_empty()) {
        (true, true) => String::new(),
        (true, false) => key,
        (false, true) => table,
        (false, false) => format!("{table}.{key}"),
    };
    if path.is_empty() {
        format!("greenhouse (line {line_no}): {msg}")
    } else {
        format!("greenhouse.{path} (line {line_no}): {msg}")
    }
}
