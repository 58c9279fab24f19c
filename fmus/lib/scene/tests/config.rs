//! Scenario `[greenhouse]` parsing: defaults, strictness, errors that name the key.

use agrisim_scene::GreenhouseConfig;

#[test]
fn empty_is_default_and_default_is_the_papers_setup() {
    let c = GreenhouseConfig::from_toml_str("").unwrap();
    assert_eq!(c, GreenhouseConfig::default());
    c.validate().unwrap();
    assert_eq!((c.length, c.width, c.height), (70.0, 55.0, 10.0));
    assert_eq!((c.active_rows, c.aisle_width), (6, 2.0));
}

#[test]
fn keys_are_read() {
    let c = GreenhouseConfig::from_toml_str(
        "rows = 10\nactive_rows = 4\nfirst_active_row = 3\nrandom_obstacles = 2\nblock_aisles = [1]\nseed = 9\n\
         ripeness = [0, 0, 0, 0, 0, 1]\n[[obstacles]]\nx = 10.0\ny = 20.0\nsize_x = 0.5\nsize_y = 0.5\n",
    )
    .unwrap();
    assert_eq!((c.rows, c.active_rows, c.first_active_row, c.random_obstacles, c.seed), (10, 4, 3, 2, 9));
    assert_eq!(c.block_aisles, vec![1]);
    assert_eq!(c.obstacles.len(), 1);
    assert_eq!(c.obstacles[0].height, 1.0);
}

fn err(s: &str) -> String {
    GreenhouseConfig::from_toml_str(s).unwrap_err()
}

#[test]
fn errors_name_the_key() {
    let cases = [
        ("rowz = 3", "rowz"),
        ("rows = \"six\"", "greenhouse.rows"),
        ("aisle_width = -1.0", "greenhouse.aisle_width"),
        ("active_rows = 7", "greenhouse.active_rows"),
        ("rows = 160", "greenhouse.width"),
        ("block_aisles = [5]", "greenhouse.block_aisles"),
        ("ripeness = [0, 0, 0, 0, 0, 0]", "greenhouse.ripeness"),
        ("fruit_height = [1.9, 1.2]", "greenhouse.fruit_height"),
        ("row_length = 80.0", "greenhouse.row_length"),
        ("[[obstacles]]\nx = 1.0\ny = 2.0\nsize_x = 0.5\nsize_y = 0.5\nheigth = 2.0", "heigth"),
        ("[[obstacles]]\nx = 1.0\ny = 2.0\nsize_x = 0.5\nsize_y = 0.5\n[[obstacles]]\nx = 1.0\ny = 2.0\nsize_x = \"big\"\nsize_y = 0.5\n", "obstacles[1].size_x"),
        ("[[obstacles]]\nx = 1.0\ny = 2.0\nsize_x = -0.5\nsize_y = 0.5", "obstacles[0]"),
        ("[[obstacles]]\nx = 1.0\ny = 2.0\nsize_x = 0.5\nsize_y = 0.5\n[[obstacles]]\nx = 1.0\ny = 2.0\nsize_y = 0.5", "obstacles[1]"),
        ("random_obstacles = 1\nrandom_obstacle_size = [0.3, 1.5]", "greenhouse.random_obstacle_size"),
    ];
    for (src, key) in cases {
        let e = err(src);
        assert!(e.contains(key), "error for {src:?} does not name {key:?}: {e}");
    }
}

#[test]
fn syntax_errors_are_reported() {
    assert!(err("rows = ").contains("greenhouse"));
}
