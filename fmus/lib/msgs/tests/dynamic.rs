//! The run-time codec ([`agrisim_msgs::dynamic`]) against the typed structs: the same bytes
//! for every type's sample, the same verdict on damaged and random bytes, and clear errors.

mod common;

use agrisim_math::Rng;
use agrisim_msgs::dynamic::{decode, encode, DynError, Value};
use agrisim_msgs::geometry_msgs::{Twist, Vector3};
use agrisim_msgs::sensor_msgs::JointState;
use agrisim_msgs::Message;
use common::samples::all_samples;

#[test]
fn every_sample_decodes_and_reencodes_to_the_same_bytes() {
    for s in all_samples() {
        let v = decode(s.type_name, &s.bytes).unwrap_or_else(|e| panic!("{}: {e}", s.name));
        assert!(matches!(v, Value::Struct(_)), "{}", s.name);
        let again = encode(s.type_name, &v).unwrap_or_else(|e| panic!("{}: {e}", s.name));
        assert_eq!(again, s.bytes, "{}: re-encoded bytes differ", s.name);
    }
}

#[test]
fn truncated_samples_fail_as_the_typed_decoder_does() {
    for s in all_samples() {
        for len in 0..s.bytes.len() {
            assert!(decode(s.type_name, &s.bytes[..len]).is_err(), "{} prefix {len} decoded", s.name);
        }
    }
}

/// Random bit flips and byte changes in every sample: the dynamic decoder accepts exactly
/// what the typed one accepts, and what it accepts re-encodes as the typed struct does.
#[test]
fn damaged_bytes_get_the_typed_verdict() {
    let samples = all_samples();
    let mut rng = Rng::new(7);
    let mut accepted = 0;
    for _ in 0..20_000 {
        let s = &samples[rng.below(samples.len() as u64) as usize];
        let mut b = s.bytes.clone();
        for _ in 0..1 + rng.below(3) {
            let k = 4 + rng.below((b.len() - 4).max(1) as u64) as usize;
            if k < b.len() {
                b[k] = if rng.below(2) == 0 { b[k] ^ (1 << rng.below(8)) } else { rng.below(4) as u8 };
            }
        }
        let typed = (s.decode)(&b);
        let dynamic = decode(s.type_name, &b);
        assert_eq!(typed.is_ok(), dynamic.is_ok(), "{}: typed {typed:?}, dynamic {:?}", s.name, dynamic.as_ref().err());
        if let Ok(v) = dynamic {
            accepted += 1;
            let ours = encode(s.type_name, &v).expect("a decoded value encodes");
            // Bytes, not values: a flipped bit may make a NaN, which is not equal to itself.
            let twice = encode(s.type_name, &decode(s.type_name, &ours).expect("decodes")).expect("encodes");
            assert_eq!(twice, ours, "{}", s.name);
        }
    }
    assert!(accepted > 1000, "only {accepted} damaged samples decoded: the comparison is too thin");
}

#[test]
fn missing_fields_take_ros_defaults() {
    let lin = Value::Struct(vec![("x".into(), Value::Float(0.5))]);
    let bytes = encode("geometry_msgs/msg/Twist", &Value::Struct(vec![("linear".into(), lin)])).unwrap();
    let typed = Twist { linear: Vector3 { x: 0.5, y: 0.0, z: 0.0 }, ..Default::default() };
    assert_eq!(bytes, typed.to_cdr());
    // The short `pkg/Type` form names the same type.
    assert_eq!(encode("sensor_msgs/JointState", &Value::Struct(vec![])).unwrap(), JointState::default().to_cdr());
}

#[test]
fn bad_values_are_named() {
    let twist = |f: &str, v: Value| Value::Struct(vec![("linear".into(), Value::Struct(vec![(f.into(), v)]))]);
    let e = encode("geometry_msgs/msg/Twist", &twist("w", Value::Float(1.0))).unwrap_err();
    assert!(matches!(&e, DynError::Field { path, .. } if path == "linear.w"), "{e}");
    assert!(e.to_string().contains("fields: x, y, z"), "{e}");
    let e = encode("geometry_msgs/msg/Twist", &twist("x", Value::String("fast".into()))).unwrap_err();
    assert_eq!(e.to_string(), "field linear.x: expected a number, got a string");
    let e =
        encode("sensor_msgs/msg/PointField", &Value::Struct(vec![("datatype".into(), Value::Int(300))])).unwrap_err();
    assert_eq!(e.to_string(), "field datatype: 300 is out of range [0, 255]");
    let e = encode(
        "geometry_msgs/msg/PoseWithCovariance",
        &Value::Struct(vec![("covariance".into(), Value::Array(vec![Value::Float(1.0); 3]))]),
    )
    .unwrap_err();
    assert_eq!(e.to_string(), "field covariance: expected 36 elements, got 3");
    assert_eq!(
        encode("geometry_msgs/msg/Twistt", &Value::Struct(vec![])).unwrap_err(),
        DynError::UnknownType("geometry_msgs/msg/Twistt".into())
    );
    assert!(decode("nope", &[0, 1, 0, 0]).is_err());
}
