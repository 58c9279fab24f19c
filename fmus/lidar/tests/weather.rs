//! The LiDAR in fog and rain: returns fade with two-way extinction, so the farthest return
//! comes nearer and fewer rays return; clear air is untouched; results stay seeded.

use agrisim_fmi::{Model, Quiet, Store, Value};
use agrisim_fmu_lidar::cloud;
use agrisim_fmu_lidar::lidar::detected;
use agrisim_fmu_lidar::ports::*;
use agrisim_fmu_lidar::Lidar;
use agrisim_msgs::sensor_msgs::PointCloud2;
use agrisim_msgs::Message;

/// (returns, farthest return [m], cloud bytes) of the second frame from the aisle start of
/// the default greenhouse, looking down the aisle.
fn frame(environment: &str) -> (i32, f64, Vec<u8>, f64) {
    let mut io = Store::new(Lidar::VARIABLES);
    *io.value_mut(ENVIRONMENT) = Value::String(environment.into());
    io.set_f64(BASE_X, 2.0);
    io.set_f64(BASE_Y, 27.5);
    let mut m = Lidar::new();
    m.initialize(&mut io, 0.0, &mut Quiet).unwrap();
    for k in 0..10 {
        m.do_step(&mut io, k as f64 * 0.02, 0.02, &mut Quiet).unwrap();
    }
    let c = PointCloud2::from_cdr(agrisim_fmi::port::latest(&io, POINTS)).unwrap();
    let far = cloud::read(&c)
        .unwrap()
        .iter()
        .map(|p| p.xyz.iter().map(|v| (*v as f64).powi(2)).sum::<f64>().sqrt())
        .fold(0.0, f64::max);
    (io.i32(RETURNS_IN_FRAME), far, c.data, io.f64(VISIBILITY))
}

#[test]
fn fog_shortens_the_range_and_drops_returns() {
    let (n_clear, far_clear, bytes_clear, _) = frame("");
    let (n_sunny, _, bytes_sunny, v_sunny) = frame("weather = \"clear\"\nhumidity = 50.0");
    let (n_fog, far_fog, bytes_fog, v_fog) = frame("weather = \"fog\"\nvisibility = 30.0");
    let (n_thick, far_thick, _, _) = frame("weather = \"fog\"\nvisibility = 10.0");
    println!("returns / farthest: none {n_clear} {far_clear:.1} m, fog 30 m {n_fog} {far_fog:.1} m, fog 10 m {n_thick} {far_thick:.1} m");
    assert!(far_clear > 25.0, "the aisle is long: {far_clear}");
    // Haze at 50 % humidity (visibility ~28 km) barely matters at greenhouse ranges.
    assert!(v_sunny > 20_000.0 && n_sunny >= n_clear - n_clear / 200, "{n_sunny} vs {n_clear}");
    assert!((v_fog - 30.0).abs() < 1e-9);
    // Where exp(-2 beta r) (40 / r)^2 = 1: beta = 3.912 / 30 -> 10.9 m; beta = 3.912 / 10 -> 5.0 m.
    let limit = |v: f64| {
        let beta = 3.912 / v;
        let mut r = 0.1;
        while detected(r + 0.001, 40.0, beta) {
            r += 0.001;
        }
        r
    };
    assert!(far_fog <= limit(30.0) + 0.1 && far_fog > limit(30.0) - 2.0, "{far_fog} vs {}", limit(30.0));
    assert!(far_thick <= limit(10.0) + 0.1 && far_thick < far_fog, "{far_thick}");
    assert!(n_thick < n_fog && n_fog < n_clear, "{n_thick} {n_fog} {n_clear}");
    assert_ne!(bytes_fog, bytes_clear);
    assert_eq!(bytes_fog, frame("weather = \"fog\"\nvisibility = 30.0").2, "seeded: same bytes");
    assert_ne!(bytes_sunny.len(), 0);
}

#[test]
fn rain_shortens_the_range_a_little() {
    let (n_clear, ..) = frame("weather = \"clear\"");
    let (n_rain, _, _, v) = frame("weather = \"rain\"\nrain_rate = 50.0");
    assert!(v < 2_000.0, "visibility in heavy rain {v}");
    assert!(n_rain <= n_clear, "{n_rain} {n_clear}");
}

#[test]
fn a_bad_environment_names_the_key() {
    let mut io = Store::new(Lidar::VARIABLES);
    *io.value_mut(ENVIRONMENT) = Value::String("visibility = -3.0".into());
    let e = Lidar::new().initialize(&mut io, 0.0, &mut Quiet).unwrap_err();
    assert!(e.contains("environment") && e.contains("visibility"), "{e}");
}
