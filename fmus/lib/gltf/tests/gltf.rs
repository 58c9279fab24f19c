//! The .glb file: framing (header, JSON and BIN chunks) and content (one mesh per kind,
//! accessors that fit the buffer, indices in range).

use agrisim_gltf::{glb_bytes, parse_glb, triangles, write_glb};
use agrisim_scene::{generate, GreenhouseConfig, Kind};

fn scene() -> Vec<agrisim_scene::Object> {
    let c =
        GreenhouseConfig::from_toml_str("rows = 3\nactive_rows = 3\nrow_length = 4.0\nrandom_obstacles = 1").unwrap();
    generate(&c, 1).objects
}

/// Value of `"key":<number>` after position `from` in `json`.
fn number_after(json: &str, from: usize, key: &str) -> usize {
    let k = format!("\"{key}\":");
    let at = json[from..].find(&k).unwrap() + from + k.len();
    json[at..].chars().take_while(|c| c.is_ascii_digit()).collect::<String>().parse().unwrap()
}

#[test]
fn glb_framing_and_content() {
    let objs = scene();
    let path = std::env::temp_dir().join(format!("agrisim-gh-test-{}.glb", std::process::id()));
    write_glb(&objs, &path).unwrap();
    let bytes = std::fs::read(&path).unwrap();
    std::fs::remove_file(&path).ok();
    assert_eq!(bytes, glb_bytes(&objs), "deterministic");
    let (json, bin) = parse_glb(&bytes).unwrap();
    assert!(json.starts_with("{\"asset\":{\"version\":\"2.0\""));
    assert_eq!(number_after(&json, json.find("\"buffers\"").unwrap(), "byteLength"), bin.len());

    // One mesh per kind present; fruit per ripeness stage.
    let mut kinds: Vec<Kind> = objs.iter().map(|o| o.kind).collect();
    kinds.sort();
    kinds.dedup();
    assert_eq!(json.matches("\"primitives\"").count(), kinds.len());
    for s in 1..=6 {
        if kinds.contains(&Kind::Fruit { ripeness: s }) {
            assert!(json.contains(&format!("\"name\":\"Fruit{s}\"")));
        }
    }

    // Every buffer view lies inside BIN; index data are in range of their positions.
    let views_at = json.find("\"bufferViews\"").unwrap();
    let acc_at = json.find("\"accessors\"").unwrap();
    let mut tri_total = 0;
    let mut pos = views_at;
    let mut k = 0;
    while let Some(i) = json[pos..views_at + json[views_at..].find(']').unwrap()].find("\"byteOffset\"") {
        let off = number_after(&json, pos + i, "byteOffset");
        let len = number_after(&json, pos + i, "byteLength");
        assert!(off + len <= bin.len() && off & 3 == 0);
        if k % 2 == 1 {
            // Index view: u32s below the vertex count of the paired POSITION accessor.
            let acc_pos = json[acc_at..].match_indices("\"count\":").nth(k - 1).unwrap().0 + acc_at;
            let nverts = number_after(&json, acc_pos, "count");
            for c in bin[off..off + len].chunks(4) {
                assert!((u32::from_le_bytes([c[0], c[1], c[2], c[3]]) as usize) < nverts);
            }
            tri_total += len / 12;
        }
        pos += i + 1;
        k += 1;
    }
    assert_eq!(tri_total, triangles(&objs).1.len());
}

#[test]
fn triangles_lie_on_the_primitives() {
    let objs = scene();
    let (v, t) = triangles(&objs);
    assert!(t.iter().all(|tri| tri.iter().all(|&i| (i as usize) < v.len())));
    // Box: 12 triangles; cylinder 64; sphere 16 * 8 * 2 - 32 = 224.
    let f = &objs.iter().find(|o| matches!(o.kind, Kind::Fruit { .. })).unwrap();
    let (fv, ft) = triangles(std::slice::from_ref(f));
    assert_eq!(ft.len(), 224);
    let c = f.placement.translation;
    let agrisim_scene::Shape::Sphere { radius } = f.shape else { panic!() };
    for p in fv {
        let d = ((p[0] as f64 - c[0]).powi(2) + (p[1] as f64 - c[1]).powi(2) + (p[2] as f64 - c[2]).powi(2)).sqrt();
        assert!((d - radius).abs() < 1e-5);
    }
}

#[test]
fn parse_rejects_damage() {
    let bytes = glb_bytes(&scene());
    assert!(parse_glb(&bytes[..bytes.len() - 4]).is_err());
    let mut b = bytes.clone();
    b[0] = b'x';
    assert!(parse_glb(&b).is_err());
}
