//! Calibrates perception's [`CostModel`]: replays the camera frames and TF of a recorded
//! harvest-by-sight trial through the perception node (the benchmark's configuration), times
//! each node step that took up frames (the least of `--repeat` passes, each from a fresh node)
//! and fits seconds per unit of the counted work by non-negative least squares.
//!
//! The recording: `agrisim bench harvest --scenario models/scenarios/harvest_sight.toml
//! --trials 1 --scenes 1 --seed 1 --jobs 1 --record full --out /tmp/rec`, then
//! `cargo run --release -p agrisim-perception --example perception_cost --
//! /tmp/rec/trials/0000.mcap [--repeat 3]`.

use agrisim_bus::{Bus, Node};
use agrisim_msgs::sensor_msgs::Image;
use agrisim_msgs::Message;
use agrisim_perception::{CostModel, DetectWork, Perception, PerceptionConfig};
use std::time::Instant;

/// Messages of `topics` in log order: (time, topic, type, CDR).
fn replay(path: &str, keep: impl Fn(&str) -> bool) -> Vec<(i64, String, String, Vec<u8>)> {
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("{path}: {e}"));
    let mut out = Vec::new();
    for m in mcap::MessageStream::new(&bytes).expect("an MCAP file") {
        let m = m.expect("a valid record");
        if keep(&m.channel.topic) {
            let ty = m.channel.schema.as_ref().map(|s| s.name.clone()).unwrap_or_default();
            out.push((m.log_time as i64, m.channel.topic.clone(), ty, m.data.to_vec()));
        }
    }
    out.sort_by_key(|m| m.0);
    out
}

/// Non-negative least squares by elimination of negative coefficients: `x >= 0` minimizing
/// |A x - b| over the columns kept.
fn nnls(a: &[Vec<f64>], b: &[f64]) -> Vec<f64> {
    let n = a[0].len();
    let mut active: Vec<bool> = vec![true; n];
    loop {
        let cols: Vec<usize> = (0..n).filter(|&j| active[j]).collect();
        let m = cols.len();
        // Normal equations, columns scaled to unit norm for conditioning.
        let scale: Vec<f64> =
            cols.iter().map(|&j| a.iter().map(|r| r[j] * r[j]).sum::<f64>().sqrt().max(1e-300)).collect();
        let mut ata = nalgebra::DMatrix::<f64>::zeros(m, m);
        let mut atb = nalgebra::DVector::<f64>::zeros(m);
        for (r, y) in a.iter().zip(b) {
            for p in 0..m {
                let xp = r[cols[p]] / scale[p];
                atb[p] += xp * y;
                for q in 0..m {
                    ata[(p, q)] += xp * r[cols[q]] / scale[q];
                }
            }
        }
        let sol = ata
            .clone()
            .cholesky()
            .map(|c| c.solve(&atb))
            .unwrap_or_else(|| ata.pseudo_inverse(1e-12).expect("pinv") * &atb);
        let mut x = vec![0.0; n];
        for p in 0..m {
            x[cols[p]] = sol[p] / scale[p];
        }
        match (0..n).filter(|&j| active[j] && x[j] < 0.0).min_by(|&i, &j| x[i].total_cmp(&x[j])) {
            Some(j) => active[j] = false,
            None => return x,
        }
    }
}

/// The work and least wall time of every node step that took up frames, over `repeat`
/// passes of `msgs`, each from a fresh node.
fn measure(msgs: &[(i64, String, String, Vec<u8>)], repeat: usize) -> Vec<(DetectWork, f64)> {
    let cameras = ["camera_left", "camera_right"];
    // The node steps at the bus's message instants (0.1 s), as in a run.
    let period = 100_000_000i64;
    let mut steps: Vec<(DetectWork, f64)> = Vec::new();
    for pass in 0..repeat {
        let config = PerceptionConfig { map_period: 0.5, ..PerceptionConfig::for_cameras(&cameras) };
        let mut node = Perception::new(config).with_cost(CostModel::FREE);
        let mut bus = Bus::default();
        let (mut i, mut k) = (0, 0usize);
        let end = msgs.last().map_or(0, |m| m.0);
        let mut t = 0i64;
        while t <= end + period {
            while i < msgs.len() && msgs[i].0 <= t {
                let (time, topic, ty, cdr) = &msgs[i];
                bus.publish_raw(topic, ty, *time, cdr.clone());
                i += 1;
            }
            let before = node.work;
            let start = Instant::now();
            node.step(t, &mut bus).expect("perception step");
            let wall = start.elapsed().as_secs_f64();
            bus.drain();
            let w = node.work;
            let work = DetectWork {
                pixels: w.pixels - before.pixels,
                conversions: w.conversions - before.conversions,
                candidates: w.candidates - before.candidates,
                fit_points: w.fit_points - before.fit_points,
                surface_tests: w.surface_tests - before.surface_tests,
                haze_samples: w.haze_samples - before.haze_samples,
                cleared: w.cleared - before.cleared,
            };
            if work.pixels > 0 {
                if pass == 0 {
                    steps.push((work, wall));
                } else {
                    assert_eq!(steps[k].0, work, "the work of a step is deterministic");
                    steps[k].1 = steps[k].1.min(wall);
                }
                k += 1;
            }
            t += period;
        }
    }
    steps
}

fn row(w: &DetectWork) -> Vec<f64> {
    vec![w.pixels as f64, w.conversions as f64, w.candidates as f64, w.fit_points as f64, w.surface_tests as f64]
}

fn pct(v: &mut [f64], p: f64) -> f64 {
    v.sort_by(f64::total_cmp);
    v[((v.len() - 1) as f64 * p).round() as usize]
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let Some(path) = args.first() else {
        eprintln!("usage: perception_cost RUN.mcap [--repeat N]");
        std::process::exit(2);
    };
    let repeat: usize =
        args.iter().position(|a| a == "--repeat").and_then(|i| args.get(i + 1)?.parse().ok()).unwrap_or(3);
    let msgs =
        replay(path, |t| t == "/tf" || t == "/tf_static" || t.contains("/color/") || t.contains("/aligned_depth"));
    // The same frames with black colour images (nothing fruit-coloured): the scan's own cost,
    // which the real frames (all with fruit-coloured pixels) cannot tell from the rest.
    let blank: Vec<_> = (msgs.iter())
        .map(|(t, topic, ty, cdr)| {
            if !topic.ends_with("/color/image_raw") {
                return (*t, topic.clone(), ty.clone(), cdr.clone());
            }
            let mut img = Image::from_cdr(cdr).expect("an Image");
            img.data.iter_mut().for_each(|b| *b = 0);
            (*t, topic.clone(), ty.clone(), img.to_cdr())
        })
        .collect();
    let real = measure(&msgs, repeat);
    let steps: Vec<(DetectWork, f64)> = real.iter().copied().chain(measure(&blank, repeat)).collect();
    println!("real frames' steps: {}, black frames' steps: {}", real.len(), steps.len() - real.len());
    assert!(steps.len() > 10, "too few frames in {path}");
    let a: Vec<Vec<f64>> = steps.iter().map(|(w, _)| row(w)).collect();
    // The fog estimate's cost is calibrated apart (`haze_cost`: its samples are as many in
    // every frame, so here they cannot be told from the scan's pixels) and taken off.
    let c = CostModel::CALIBRATED;
    let haze = CostModel { per_haze_sample: c.per_haze_sample, per_cleared: c.per_cleared, ..CostModel::FREE };
    let b: Vec<f64> = steps.iter().map(|(w, s)| s - haze.seconds(w)).collect();
    let x = nnls(&a, &b);
    // Two halves of the set: the even and the odd steps.
    let pick = |odd: usize| -> (Vec<Vec<f64>>, Vec<f64>) {
        (a.iter().skip(odd).step_by(2).cloned().collect(), b.iter().skip(odd).step_by(2).copied().collect())
    };
    let ((a1, b1), (a2, b2)) = (pick(0), pick(1));
    let (x1, x2) = (nnls(&a1, &b1), nnls(&a2, &b2));
    let model = |x: &[f64], r: &[f64]| r.iter().zip(x).map(|(u, c)| u * c).sum::<f64>();
    let mut rel: Vec<f64> = a.iter().zip(&b).take(real.len()).map(|(r, s)| model(&x, r) / s - 1.0).collect();
    let total_model: f64 = a.iter().map(|r| model(&x, r)).sum();
    let total: f64 = b.iter().sum();
    let names = ["per_pixel", "per_conversion", "per_candidate", "per_fit_point", "per_surface_test"];
    let real_total: f64 = b[..real.len()].iter().sum();
    println!(
        "real frames: measured {:.3} s in all, {:.2} ms per step",
        real_total,
        1e3 * real_total / real.len() as f64
    );
    for (j, n) in names.iter().enumerate() {
        println!("{n}: {:.3e} (halves {:.3e}, {:.3e})", x[j], x1[j], x2[j]);
    }
    println!(
        "model vs measured per real step {:+.0} % .. {:+.0} % (p5..p95); total {:+.1} % (with black {:+.1} %)",
        100.0 * pct(&mut rel, 0.05),
        100.0 * pct(&mut rel, 0.95),
        100.0 * (a[..real.len()].iter().map(|r| model(&x, r)).sum::<f64>() / real_total - 1.0),
        100.0 * (total_model / total - 1.0)
    );
}
