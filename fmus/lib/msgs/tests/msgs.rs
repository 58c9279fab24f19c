//! Round trips, hand-derived golden bytes, error reporting, schemas, and a fuzz-style
//! no-panic test over every type's decoder.

mod common;

use agrisim_math::Rng;
use agrisim_msgs::builtin_interfaces::Time;
use agrisim_msgs::geometry_msgs::*;
use agrisim_msgs::rosgraph_msgs::Clock;
use agrisim_msgs::sensor_msgs::JointState;
use agrisim_msgs::std_msgs::Header;
use agrisim_msgs::tf2_msgs::TFMessage;
use agrisim_msgs::*;
use common::samples::{all_samples, Sample};
use std::collections::BTreeSet;

// ---------------------------------------------------------------- round trips & coverage

#[test]
fn every_sample_round_trips() {
    for s in all_samples() {
        assert_eq!(&s.bytes[..4], &CDR_LE_HEADER, "{}", s.name);
        (s.check)(&s.bytes).unwrap_or_else(|e| panic!("{}: {e}", s.name));
        // Trailing padding (rmw pads to 4 bytes) must be accepted.
        let mut padded = s.bytes.clone();
        padded.extend_from_slice(&[0, 0, 0]);
        (s.check)(&padded).unwrap_or_else(|e| panic!("{} padded: {e}", s.name));
    }
}

#[test]
fn samples_cover_every_type() {
    let sampled: BTreeSet<&str> = all_samples().iter().map(|s| s.type_name).collect();
    let all: BTreeSet<&str> = all_type_names().iter().copied().collect();
    assert_eq!(sampled, all);
    assert_eq!(all.len(), 60);
}

#[test]
fn defaults_round_trip() {
    fn rt<M: Message + Default + PartialEq + std::fmt::Debug>() {
        let m = M::default();
        assert_eq!(M::from_cdr(&m.to_cdr()).unwrap(), m, "{}", M::TYPE_NAME);
    }
    rt::<Time>();
    rt::<Header>();
    rt::<Quaternion>();
    rt::<PoseWithCovariance>();
    rt::<TwistWithCovariance>();
    rt::<agrisim_msgs::nav_msgs::Odometry>();
    rt::<agrisim_msgs::nav_msgs::Path>();
    rt::<TFMessage>();
    rt::<Clock>();
    rt::<JointState>();
    rt::<agrisim_msgs::agrisim::Signals>();
    rt::<agrisim_msgs::agrisim::FmuStatus>();
    assert_eq!(Quaternion::default().w, 1.0);
}

// ---------------------------------------------------------------- golden bytes

fn f64le(v: f64) -> [u8; 8] {
    v.to_le_bytes()
}

#[test]
fn golden_twist_is_header_plus_48_bytes() {
    let t = Twist { linear: Vector3 { x: 1.0, y: 2.0, z: 3.0 }, angular: Vector3 { x: -1.0, y: 0.0, z: 0.5 } };
    let expected: Vec<u8> = [
        vec![0x00, 0x01, 0x00, 0x00],
        vec![0, 0, 0, 0, 0, 0, 0xf0, 0x3f], // 1.0
        vec![0, 0, 0, 0, 0, 0, 0x00, 0x40], // 2.0
        vec![0, 0, 0, 0, 0, 0, 0x08, 0x40], // 3.0
        vec![0, 0, 0, 0, 0, 0, 0xf0, 0xbf], // -1.0
        vec![0, 0, 0, 0, 0, 0, 0x00, 0x00], // 0.0
        vec![0, 0, 0, 0, 0, 0, 0xe0, 0x3f], // 0.5
    ]
    .concat();
    assert_eq!(t.to_cdr(), expected);
    assert_eq!(expected.len(), 52);
}

#[test]
fn golden_header_and_clock() {
    let h = Header::new(Time::new(1, 2), "ab");
    assert_eq!(h.to_cdr(), vec![0, 1, 0, 0, 1, 0, 0, 0, 2, 0, 0, 0, 3, 0, 0, 0, b'a', b'b', 0]);
    // Empty string is length 1 + NUL, not length 0.
    assert_eq!(Header::default().to_cdr(), vec![0, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0]);
    let c = Clock { clock: Time::new(5, 6) };
    assert_eq!(c.to_cdr(), vec![0, 1, 0, 0, 5, 0, 0, 0, 6, 0, 0, 0]);
    assert_eq!(Time::new(-2, 0).to_cdr(), vec![0, 1, 0, 0, 0xfe, 0xff, 0xff, 0xff, 0, 0, 0, 0]);
}

#[test]
fn golden_pose_stamped_pads_after_string() {
    // Header body = 8 (stamp) + 4 (len) + 3 ("ab\0") = 15 bytes; Pose's first f64 is
    // aligned to 8 relative to the end of the encapsulation header -> 1 pad byte.
    let p = PoseStamped {
        header: Header::new(Time::new(1, 2), "ab"),
        pose: Pose { position: Point { x: 1.0, y: 2.0, z: 3.0 }, orientation: Quaternion::IDENTITY },
    };
    let mut expected = vec![0, 1, 0, 0, 1, 0, 0, 0, 2, 0, 0, 0, 3, 0, 0, 0, b'a', b'b', 0, 0];
    for v in [1.0, 2.0, 3.0, 0.0, 0.0, 0.0, 1.0] {
        expected.extend_from_slice(&f64le(v));
    }
    assert_eq!(p.to_cdr(), expected);
    assert_eq!(expected.len(), 4 + 16 + 56);
}

#[test]
fn golden_transform_stamped_pads_twice() {
    // stamp 8 + "odom" (4+5) = 17 -> pad 3 -> child "base" len at 20, bytes 24..29
    // -> pad 3 -> 7 f64 from 32.
    let t = TransformStamped {
        header: Header::new(Time::new(0, 0), "odom"),
        child_frame_id: "base".into(),
        transform: Transform { translation: Vector3 { x: 1.0, y: 0.0, z: 0.0 }, rotation: Quaternion::IDENTITY },
    };
    let mut expected = vec![0, 1, 0, 0];
    expected.extend_from_slice(&[0; 8]);
    expected.extend_from_slice(&[5, 0, 0, 0, b'o', b'd', b'o', b'm', 0, 0, 0, 0]);
    expected.extend_from_slice(&[5, 0, 0, 0, b'b', b'a', b's', b'e', 0, 0, 0, 0]);
    for v in [1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0] {
        expected.extend_from_slice(&f64le(v));
    }
    assert_eq!(t.to_cdr(), expected);
    assert_eq!(expected.len(), 4 + 88);
}

#[test]
fn golden_joint_state_sequences() {
    let j = JointState {
        header: Header::default(),
        name: vec!["j".into()],
        position: vec![0.5],
        velocity: vec![],
        effort: vec![],
    };
    let mut expected = vec![0, 1, 0, 0];
    expected.extend_from_slice(&[0; 8]); // stamp
    expected.extend_from_slice(&[1, 0, 0, 0, 0, 0, 0, 0]); // "" + 3 pad (rel 13 -> 16)
    expected.extend_from_slice(&[1, 0, 0, 0]); // name count
    expected.extend_from_slice(&[2, 0, 0, 0, b'j', 0, 0, 0]); // "j" + 2 pad (rel 26 -> 28)
    expected.extend_from_slice(&[1, 0, 0, 0]); // position count, ends at rel 32
    expected.extend_from_slice(&f64le(0.5));
    expected.extend_from_slice(&[0, 0, 0, 0, 0, 0, 0, 0]); // velocity, effort counts
    assert_eq!(j.to_cdr(), expected);
    assert_eq!(JointState::from_cdr(&expected).unwrap(), j);
}

#[test]
fn reads_big_endian() {
    let be = [0u8, 0, 0, 0, 0, 0, 0, 5, 0, 0, 0, 6];
    assert_eq!(Clock::from_cdr(&be).unwrap().clock, Time::new(5, 6));
}

// ---------------------------------------------------------------- errors

#[test]
fn errors_name_what_and_where() {
    let e = Clock::from_cdr(&[0, 1]).unwrap_err();
    assert_eq!(e, CdrError::MissingHeader { len: 2 });

    let e = Clock::from_cdr(&[0, 0x0a, 0, 0, 5, 0, 0, 0, 6, 0, 0, 0]).unwrap_err();
    assert!(matches!(e, CdrError::UnsupportedEncapsulation { kind: [0, 0x0a] }));
    assert!(e.to_string().contains("byte 0"), "{e}");

    let e = Clock::from_cdr(&[0, 1, 0, 0, 5, 0, 0, 0, 6]).unwrap_err();
    assert_eq!(e, CdrError::UnexpectedEof { what: "uint32", offset: 8, needed: 4, available: 1 });
    assert!(e.to_string().contains("byte 8"), "{e}");

    // String length larger than the buffer.
    let e = Header::from_cdr(&[0, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0xff, 0xff, 0xff, 0x7f, b'a']).unwrap_err();
    assert!(matches!(e, CdrError::LengthTooLarge { what: "string length", offset: 12, .. }), "{e:?}");
    assert!(e.to_string().contains("byte 12"), "{e}");

    // Missing NUL.
    let e = Header::from_cdr(&[0, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 2, 0, 0, 0, b'a', b'b']).unwrap_err();
    assert_eq!(e, CdrError::MissingNul { offset: 17, found: b'b' });

    // Invalid UTF-8.
    let e = Header::from_cdr(&[0, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 3, 0, 0, 0, 0xc3, 0x28, 0]).unwrap_err();
    assert_eq!(e, CdrError::InvalidUtf8 { offset: 16 });

    // Huge sequence count: rejected before allocating.
    let e = TFMessage::from_cdr(&[0, 1, 0, 0, 0xff, 0xff, 0xff, 0xff, 0, 0, 0, 0]).unwrap_err();
    assert!(
        matches!(e, CdrError::LengthTooLarge { what: "sequence count", offset: 4, length: 0xffff_ffff, .. }),
        "{e:?}"
    );

    // A zero string length is tolerated as "" (Fast CDR does the same).
    let h = Header::from_cdr(&[0, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0]).unwrap();
    assert_eq!(h.frame_id, "");
}

#[test]
fn reader_primitives_and_bool() {
    let mut w = CdrWriter::new();
    w.write_u8(7);
    w.write_u16(0x1234);
    w.write_bool(true);
    w.write_i64(-3);
    w.write_f32(1.5);
    w.write_i8(-1);
    w.write_i16(-2);
    w.write_u64(9);
    let b = w.into_bytes();
    // u8@0, pad, u16@2, bool@4, pad to 8, i64@8, f32@16, i8@20, pad, i16@22, u64@24 (+4 header)
    assert_eq!(b.len(), 4 + 32);
    let mut r = CdrReader::new(&b).unwrap();
    assert_eq!(r.read_u8().unwrap(), 7);
    assert_eq!(r.read_u16().unwrap(), 0x1234);
    assert!(r.read_bool().unwrap());
    assert_eq!(r.read_i64().unwrap(), -3);
    assert_eq!(r.read_f32().unwrap(), 1.5);
    assert_eq!(r.read_i8().unwrap(), -1);
    assert_eq!(r.read_i16().unwrap(), -2);
    assert_eq!(r.read_u64().unwrap(), 9);
    assert_eq!(r.remaining(), 0);
    let bad = [0, 1, 0, 0, 2];
    let e = CdrReader::new(&bad).unwrap().read_bool().unwrap_err();
    assert_eq!(e, CdrError::InvalidBool { offset: 4, value: 2 });
}

// ---------------------------------------------------------------- time, mime

#[test]
fn time_constructors_are_exact() {
    assert_eq!(Time::from_nanos(1_700_000_000_123_456_789), Time::new(1_700_000_000, 123_456_789));
    assert_eq!(Time::from_nanos(-1_700_000_000), Time::new(-2, 300_000_000));
    assert_eq!(Time::from_nanos(i64::MAX), Time::new(i32::MAX, 999_999_999));
    assert_eq!(Time::from_nanos(i64::MIN), Time::new(i32::MIN, 0));
    // 0.02 s steps: 62 ticks of 50 Hz = 1.24 s exactly (f64 would give 1.2400000000000002).
    assert_eq!(Time::from_ticks(62, 50), Time::new(1, 240_000_000));
    assert_eq!(Time::from_ticks(3_000_000_001, 1_000_000_000), Time::new(3, 1));
    assert_eq!(Time::from_ticks(1, 3), Time::new(0, 333_333_333));
    assert_eq!(Time::from_ticks(-1, 10), Time::new(-1, 900_000_000));
    for n in [0i64, 1, 999_999_999, 1_000_000_000, -1, -999_999_999, 123_456_789_012] {
        assert_eq!(Time::from_nanos(n).to_nanos(), n);
    }
    assert_eq!(Time::new(1, 500_000_000).as_secs_f64(), 1.5);
}

#[test]
fn mime_types() {
    assert_eq!(mime_type::<Twist>(), "application/x-ros2-cdr-frames; version=1; type=geometry_msgs/msg/Twist");
    assert_eq!(Twist::MIME_TYPE, mime_type::<Twist>());
    assert_eq!(type_name_from_mime(Twist::MIME_TYPE), Some("geometry_msgs/msg/Twist"));
    assert_eq!(type_name_from_mime("application/x-ros2-cdr ;type = a/msg/B"), Some("a/msg/B"));
    assert_eq!(type_name_from_mime("application/x-ros2-cdr-frames; type=a/msg/B; version=1"), Some("a/msg/B"));
    assert_eq!(type_name_from_mime("application/x-ros2-cdr-frames; version=1"), None);
    assert_eq!(type_name_from_mime("application/octet-stream"), None);
    assert_eq!(type_name_from_mime("application/x-ros2-cdr; type="), None);
}

// ---------------------------------------------------------------- schemas

#[test]
fn schema_texts_exist_and_resolve() {
    for name in all_type_names() {
        let text = msg_text(name).unwrap();
        assert!(!text.trim().is_empty());
        let short = name.replace("/msg/", "/");
        assert_eq!(msg_text(&short), Some(text));
        let schema = ros2msg_schema(name).unwrap();
        assert_eq!(ros2msg_schema(&short).unwrap(), schema);
        assert!(schema.starts_with(text));
        // Each dependency block exactly once.
        let msg_lines: Vec<&str> = schema.lines().filter(|l| l.starts_with("MSG: ")).collect();
        let uniq: BTreeSet<&&str> = msg_lines.iter().collect();
        assert_eq!(uniq.len(), msg_lines.len(), "{name}");
        assert_eq!(schema.lines().filter(|l| *l == schema::SEPARATOR).count(), msg_lines.len());
        assert_eq!(schema::SEPARATOR.len(), 80);
    }
    assert_eq!(ros2msg_schema("nope_msgs/msg/Nothing"), None);
    assert_eq!(ros2msg_schema("garbage"), None);
}

#[test]
fn schema_order_matches_rosbag2() {
    let s = ros2msg_schema("nav_msgs/msg/Odometry").unwrap();
    let order: Vec<&str> = s.lines().filter_map(|l| l.strip_prefix("MSG: ")).collect();
    assert_eq!(
        order,
        [
            "geometry_msgs/PoseWithCovariance",
            "geometry_msgs/Pose",
            "geometry_msgs/Point",
            "geometry_msgs/Quaternion",
            "geometry_msgs/TwistWithCovariance",
            "geometry_msgs/Twist",
            "geometry_msgs/Vector3",
            "std_msgs/Header",
            "builtin_interfaces/Time",
        ]
    );
    let t = ros2msg_schema("geometry_msgs/msg/Twist").unwrap();
    assert!(t.contains("\n================================================================================\nMSG: geometry_msgs/Vector3\n"));
    assert_eq!(ros2msg_schema("builtin_interfaces/msg/Time").unwrap(), msg_text("builtin_interfaces/Time").unwrap());
}

#[test]
fn dependency_parser_rules() {
    let deps = schema::msg_dependencies(
        "my_pkg",
        "# Foo bar\nHeader header\nFoo[] foos # Bar baz\nother/msg/Baz[<=3] b\nfloat64[36] c\nstring<=5 s\nint32 X=3\n",
    );
    let deps: Vec<String> = deps.into_iter().collect();
    assert_eq!(deps, ["my_pkg/Foo", "other/Baz", "std_msgs/Header"]);
}

// ---------------------------------------------------------------- fuzz: never panic

/// Index in 0..n from the workspace's generator (noise flavour).
fn below(rng: &mut Rng, n: usize) -> usize {
    rng.below(n as u64) as usize
}

#[test]
fn truncations_always_fail_cleanly() {
    for s in all_samples() {
        for len in 0..s.bytes.len() {
            assert!((s.decode)(&s.bytes[..len]).is_err(), "{} prefix {len} decoded", s.name);
        }
    }
}

/// Decodes `buf` as `s`'s type; the message check without decoding (`check_cdr`, which
/// skips byte sequences instead of copying them) must give the same verdict and error.
fn verdict(s: &Sample, buf: &[u8], checked: &mut usize) -> bool {
    let decoded = (s.decode)(buf);
    if let Some(check) = agrisim_msgs::check_cdr(s.type_name, buf) {
        assert_eq!(check, decoded, "{}: check_cdr and the decoder disagree", s.name);
        *checked += 1;
    }
    decoded.is_ok()
}

#[test]
fn garbage_never_panics() {
    let samples = all_samples();
    let mut rng = Rng::new(0x9e37_79b9_7f4a_7c15);
    let mut cases = 0usize;
    let mut ok = 0usize;
    let mut checked = 0usize;
    // Random byte strings, mostly behind a valid header so the body decoders are reached;
    // counts/lengths are biased small so some sequences and strings actually parse.
    for _ in 0..20_000 {
        let len = below(&mut rng, 200);
        let mut buf: Vec<u8> = (0..len)
            .map(|_| {
                let r = rng.next_u64();
                if r & 3 == 0 {
                    (r >> 8) as u8
                } else {
                    ((r >> 8) % 4) as u8
                }
            })
            .collect();
        if below(&mut rng, 10) != 0 && buf.len() >= 4 {
            buf[..4].copy_from_slice(&CDR_LE_HEADER);
        }
        for s in &samples {
            cases += 1;
            ok += verdict(s, &buf, &mut checked) as usize;
        }
    }
    // Mutations of valid messages: flipped bytes, then random truncation.
    for s in &samples {
        for _ in 0..500 {
            let mut buf = s.bytes.clone();
            for _ in 0..1 + below(&mut rng, 4) {
                let i = below(&mut rng, buf.len());
                buf[i] = rng.next_u64() as u8;
            }
            if below(&mut rng, 2) == 0 {
                buf.truncate(below(&mut rng, buf.len() + 1));
            }
            for t in &samples {
                cases += 1;
                ok += verdict(t, &buf, &mut checked) as usize;
            }
        }
    }
    assert!(cases > 100_000, "{cases}");
    assert!(checked > cases / 2, "check_cdr compared on {checked} of {cases}");
    assert!(ok > 0, "fuzz never produced a decodable message: generator too weak");
    eprintln!("fuzz: {cases} decodes, {ok} succeeded, no panic");
}

#[test]
fn duration_helpers_are_exact() {
    use agrisim_msgs::builtin_interfaces::Duration;
    assert_eq!(Duration::from_nanos(-1_700_000_000), Duration::new(-2, 300_000_000));
    assert_eq!(Duration::from_secs_f64(1.7), Some(Duration::new(1, 700_000_000)));
    assert_eq!(Duration::from_secs_f64(f64::NAN), None);
    assert_eq!(Duration::new(2, 5).to_nanos(), 2_000_000_005);
    assert_eq!(Duration::new(1, 500_000_000).as_secs_f64(), 1.5);
}

#[test]
fn golden_solid_primitive_box() {
    use agrisim_msgs::shape_msgs::SolidPrimitive;
    let b = SolidPrimitive::new_box(1.0, 2.0, 3.0).to_cdr();
    let mut expected = CDR_LE_HEADER.to_vec();
    expected.extend_from_slice(&[1, 0, 0, 0]); // type + pad to 4
    expected.extend_from_slice(&3u32.to_le_bytes()); // dimensions count, ends at rel 8
    for v in [1.0f64, 2.0, 3.0] {
        expected.extend_from_slice(&v.to_le_bytes());
    }
    expected.extend_from_slice(&0u32.to_le_bytes()); // polygon.points count
    assert_eq!(b, expected);
}
