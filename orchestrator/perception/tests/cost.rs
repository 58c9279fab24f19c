//! Perception's compute charged in simulated time: a frame's outputs wait for its modelled
//! cost (to the node's step), frames that arrive while it is busy wait (the newest of each
//! camera kept), and the free model gives every output at the step its frame arrived.

use agrisim_bus::{Bus, Node, Reader};
use agrisim_msgs::builtin_interfaces::Time;
use agrisim_msgs::sensor_msgs::{CameraInfo, Image};
use agrisim_msgs::std_msgs::Header;
use agrisim_msgs::vision_msgs::Detection3DArray;
use agrisim_perception::node::{CAMERA_INFO, DEPTH, DETECTIONS, IMAGE};
use agrisim_perception::{CostModel, Perception, PerceptionConfig};

const W: usize = 64;
const H: usize = 48;
/// The node's steps: the bus's message instants (10 Hz).
const STEP: i64 = 100_000_000;

fn frame(stamp: i64) -> (Image, Image) {
    let header = Header { stamp: Time::from_nanos(stamp), frame_id: "camera_optical".into() };
    let rgb = Image {
        header: header.clone(),
        width: W as u32,
        height: H as u32,
        encoding: "rgb8".into(),
        step: (W * 3) as u32,
        data: (0..W * H).flat_map(|i| if i % 7 == 0 { [190, 26, 20] } else { [150, 145, 135] }).collect(),
        ..Default::default()
    };
    let depth = Image {
        header,
        width: W as u32,
        height: H as u32,
        encoding: "32FC1".into(),
        step: (W * 4) as u32,
        data: (0..W * H).flat_map(|_| 1.0f32.to_le_bytes()).collect(),
        ..Default::default()
    };
    (rgb, depth)
}

/// Frames stamped 0, 0.1 and 0.2 s, each published at its stamp; the node stepped every
/// 0.1 s to 0.6 s. Returns (step, stamp) of every detections message, and the node.
fn run(cost: CostModel) -> (Vec<(i64, i64)>, Perception) {
    let mut bus = Bus::default();
    let mut node = Perception::new(PerceptionConfig::default()).with_cost(cost);
    let mut reader = Reader::subscribe(&mut bus, DETECTIONS);
    let info = CameraInfo {
        header: Header { frame_id: "camera_optical".into(), ..Default::default() },
        width: W as u32,
        height: H as u32,
        k: [50.0, 0.0, 32.0, 0.0, 50.0, 24.0, 0.0, 0.0, 1.0],
        ..Default::default()
    };
    bus.publish(CAMERA_INFO, 0, &info);
    let mut out = vec![];
    for k in 0..=6 {
        let t = k * STEP;
        if k <= 2 {
            let (rgb, depth) = frame(t);
            bus.publish(IMAGE, t, &rgb);
            bus.publish(DEPTH, t, &depth);
        }
        node.step(t, &mut bus).unwrap();
        for m in reader.take::<Detection3DArray>(&mut bus).unwrap() {
            out.push((t, m.header.stamp.to_nanos()));
        }
    }
    (out, node)
}

#[test]
fn outputs_wait_for_the_modelled_compute() {
    // 0.25 s per frame: frame 0 is done at 0.25 s, out at the step of 0.3 s; frame 0.1 s is
    // replaced while waiting by frame 0.2 s, taken up at 0.25 s, done at 0.5 s.
    let per_pixel = 0.25 / (W * H) as f64;
    let cost = CostModel { per_pixel, ..CostModel::FREE };
    let (out, node) = run(cost);
    assert_eq!(out, [(3 * STEP, 0), (5 * STEP, 2 * STEP)]);
    assert_eq!((node.frames, node.dropped), (2, 1));
    assert_eq!(node.work.pixels, 2 * (W * H) as u64);
    assert!((node.charged().seconds() - 0.5).abs() < 1e-9, "{}", node.charged().seconds());
    // A slower computer: 0.35 s per frame, frame 0 out at 0.4 s, frame 0.2 s done at 0.7 s.
    let (out, _) = run(cost.scaled(1.4));
    assert_eq!(out, [(4 * STEP, 0)]);
}

#[test]
fn free_compute_gives_every_output_at_its_step() {
    let (out, node) = run(CostModel::FREE);
    assert_eq!(out, [(0, 0), (STEP, STEP), (2 * STEP, 2 * STEP)]);
    assert_eq!((node.frames, node.dropped, node.charged().seconds()), (3, 0, 0.0));
    // The work was counted all the same, the same for each of the three identical frames.
    assert_eq!(node.work.pixels, 3 * (W * H) as u64);
    assert_eq!(node.work.candidates % 3, 0);
    assert!(node.work.candidates > 0);
}
