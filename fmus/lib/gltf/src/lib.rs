//! glTF 2.0 binary (.glb) export, written by hand: a 12-byte header, a JSON chunk and a BIN
//! chunk (Khronos glTF 2.0 specification, section 4.4 "GLB File Format Specification").
//! One mesh per kind (fruit: one per ripeness stage) with its own base colour, so a viewer
//! shows the scene at a glance. glTF is y-up; the single root node rotates agrisim's z-up map
//! frame into it (-90 deg about x), so a loader that applies node transforms sees the map
//! with its +z pointing up.

pub mod mesh;

use agrisim_scene::{Kind, Object};
use std::io::Write;
use std::path::Path;

const GLB_MAGIC: u32 = 0x4654_6C67; // "glTF"
const CHUNK_JSON: u32 = 0x4E4F_534A; // "JSON"
const CHUNK_BIN: u32 = 0x004E_4942; // "BIN\0"

/// All objects as one triangle soup in the map frame (z up), for mesh-based peers.
pub fn triangles(objects: &[Object]) -> (Vec<[f32; 3]>, Vec<[u32; 3]>) {
    let mut v = Vec::new();
    let mut t = Vec::new();
    for o in objects {
        mesh::append(o, &mut v, &mut t);
    }
    (v, t)
}

/// Base colour (linear RGBA) of a kind. Fruit by USDA ripeness stage, green (1) to red (6).
pub fn colour(kind: Kind) -> [f32; 4] {
    match kind {
        Kind::Floor => [0.35, 0.33, 0.30, 1.0],
        Kind::Wall => [0.80, 0.85, 0.90, 0.3],
        Kind::Roof => [0.85, 0.90, 0.95, 0.2],
        Kind::Post => [0.60, 0.62, 0.65, 1.0],
        Kind::Gutter => [0.70, 0.72, 0.75, 1.0],
        Kind::HeatingPipe => [0.75, 0.75, 0.78, 1.0],
        Kind::Stem => [0.30, 0.45, 0.15, 1.0],
        Kind::Leaf => [0.15, 0.45, 0.12, 1.0],
        Kind::Truss => [0.35, 0.50, 0.20, 1.0],
        Kind::Fruit { ripeness } => match ripeness {
            0 | 1 => [0.35, 0.65, 0.20, 1.0], // green
            2 => [0.70, 0.72, 0.30, 1.0],     // breakers
            3 => [0.92, 0.70, 0.30, 1.0],     // turning
            4 => [0.95, 0.50, 0.40, 1.0],     // pink
            5 => [0.90, 0.30, 0.20, 1.0],     // light red
            _ => [0.78, 0.08, 0.06, 1.0],     // red
        },
        Kind::Obstacle => [0.95, 0.60, 0.05, 1.0],
        Kind::Robot => [0.20, 0.30, 0.80, 1.0],
    }
}

fn kind_name(kind: Kind) -> String {
    match kind {
        Kind::Fruit { ripeness } => format!("Fruit{ripeness}"),
        k => format!("{k:?}"),
    }
}

/// Vertices and triangles of one mesh.
type Mesh = (Vec<[f32; 3]>, Vec<[u32; 3]>);

/// The .glb bytes of `objects`.
pub fn glb_bytes(objects: &[Object]) -> Vec<u8> {
    // Group by kind (BTreeMap: a stable, sorted order).
    let mut groups: std::collections::BTreeMap<Kind, Mesh> = Default::default();
    for o in objects {
        let g = groups.entry(o.kind).or_default();
        mesh::append(o, &mut g.0, &mut g.1);
    }
    let mut bin: Vec<u8> = Vec::new();
    let (mut views, mut accessors, mut meshes, mut materials, mut nodes) = (vec![], vec![], vec![], vec![], vec![]);
    for (mi, (kind, (v, t))) in groups.iter().enumerate() {
        let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
        for p in v {
            for i in 0..3 {
                lo[i] = lo[i].min(p[i]);
                hi[i] = hi[i].max(p[i]);
            }
        }
        let pos_off = bin.len();
        for p in v {
            for c in p {
                bin.extend_from_slice(&c.to_le_bytes());
            }
        }
        let idx_off = bin.len();
        for tri in t {
            for i in tri {
                bin.extend_from_slice(&i.to_le_bytes());
            }
        }
        let vp = views.len();
        views.push(format!(
            r#"{{"buffer":0,"byteOffset":{pos_off},"byteLength":{},"target":34962}}"#,
            idx_off - pos_off
        ));
        views.push(format!(
            r#"{{"buffer":0,"byteOffset":{idx_off},"byteLength":{},"target":34963}}"#,
            bin.len() - idx_off
        ));
        let ap = accessors.len();
        accessors.push(format!(
            r#"{{"bufferView":{vp},"componentType":5126,"count":{},"type":"VEC3","min":[{},{},{}],"max":[{},{},{}]}}"#,
            v.len(),
            lo[0],
            lo[1],
            lo[2],
            hi[0],
            hi[1],
            hi[2]
        ));
        accessors.push(format!(
            r#"{{"bufferView":{},"componentType":5125,"count":{},"type":"SCALAR"}}"#,
            vp + 1,
            3 * t.len()
        ));
        let c = colour(*kind);
        let blend = if c[3] < 1.0 { r#","alphaMode":"BLEND""# } else { "" };
        let name = kind_name(*kind);
        materials.push(format!(
            r#"{{"name":"{name}","pbrMetallicRoughness":{{"baseColorFactor":[{},{},{},{}],"metallicFactor":0.0,"roughnessFactor":0.8}}{blend},"doubleSided":true}}"#,
            c[0], c[1], c[2], c[3]
        ));
        meshes.push(format!(
            r#"{{"name":"{name}","primitives":[{{"attributes":{{"POSITION":{ap}}},"indices":{},"material":{mi},"mode":4}}]}}"#,
            ap + 1
        ));
        nodes.push(format!(r#"{{"name":"{name}","mesh":{mi}}}"#));
    }
    let children: Vec<String> = (1..=nodes.len()).map(|i| i.to_string()).collect();
    let h = std::f64::consts::FRAC_1_SQRT_2;
    let root = format!(r#"{{"name":"map (z up)","rotation":[{},0,0,{}],"children":[{}]}}"#, -h, h, children.join(","));
    nodes.insert(0, root);
    let json = format!(
        concat!(
            r#"{{"asset":{{"version":"2.0","generator":"agrisim-gltf"}},"scene":0,"scenes":[{{"nodes":[0]}}],"#,
            r#""nodes":[{}],"meshes":[{}],"materials":[{}],"accessors":[{}],"bufferViews":[{}],"buffers":[{{"byteLength":{}}}]}}"#
        ),
        nodes.join(","),
        meshes.join(","),
        materials.join(","),
        accessors.join(","),
        views.join(","),
        bin.len()
    );
    let mut json = json.into_bytes();
    while json.len() & 3 != 0 {
        json.push(b' ');
    }
    while bin.len() & 3 != 0 {
        bin.push(0);
    }
    let total = 12 + 8 + json.len() + 8 + bin.len();
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(&GLB_MAGIC.to_le_bytes());
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(json.len() as u32).to_le_bytes());
    out.extend_from_slice(&CHUNK_JSON.to_le_bytes());
    out.extend_from_slice(&json);
    out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
    out.extend_from_slice(&CHUNK_BIN.to_le_bytes());
    out.extend_from_slice(&bin);
    out
}

/// Writes `objects` as a .glb file.
pub fn write_glb(objects: &[Object], path: &Path) -> std::io::Result<()> {
    let bytes = glb_bytes(objects);
    let mut f = std::io::BufWriter::new(std::fs::File::create(path)?);
    f.write_all(&bytes)?;
    f.flush()
}

/// Splits .glb bytes into (JSON text, BIN chunk), checking the header and chunk framing.
pub fn parse_glb(bytes: &[u8]) -> Result<(String, Vec<u8>), String> {
    let u32_at = |o: usize| -> Result<u32, String> {
        bytes
            .get(o..o + 4)
            .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            .ok_or_else(|| format!("truncated at byte {o}"))
    };
    if u32_at(0)? != GLB_MAGIC {
        return Err("bad magic".into());
    }
    if u32_at(4)? != 2 {
        return Err("not glTF version 2".into());
    }
    if u32_at(8)? as usize != bytes.len() {
        return Err(format!("header length {} != file length {}", u32_at(8)?, bytes.len()));
    }
    let jl = u32_at(12)? as usize;
    if u32_at(16)? != CHUNK_JSON || jl & 3 != 0 {
        return Err("first chunk must be JSON, 4-byte aligned".into());
    }
    let json = std::str::from_utf8(bytes.get(20..20 + jl).ok_or("truncated JSON chunk")?).map_err(|e| e.to_string())?;
    let bo = 20 + jl;
    let bl = u32_at(bo)? as usize;
    if u32_at(bo + 4)? != CHUNK_BIN || bl & 3 != 0 {
        return Err("second chunk must be BIN, 4-byte aligned".into());
    }
    let bin = bytes.get(bo + 8..bo + 8 + bl).ok_or("truncated BIN chunk")?.to_vec();
    if bo + 8 + bl != bytes.len() {
        return Err("trailing bytes after BIN chunk".into());
    }
    Ok((json.to_string(), bin))
}
