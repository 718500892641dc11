//! Writes `scenes/gltf/spheres.gltf`, the glTF example of the README: three spheres of
//! glTF materials (a rough gold metal, a red dielectric and a KHR_materials_transmission
//! glass) on a textured floor (an embedded PNG checker with KHR_texture_transform), lit
//! by a KHR_lights_punctual spot and a point light, seen through a perspective camera.
//! Buffers and images are embedded as base64 `data:` URIs, so the file stands alone.
//!
//! ```text
//! cargo run --release -p candela-scene --example make_gltf_example
//! ```

use serde_json::json;

/// A UV sphere of radius 1: positions, normals, uvs and u32 indices.
fn sphere(rings: u32, segments: u32) -> (Vec<f32>, Vec<f32>, Vec<f32>, Vec<u32>) {
    let (mut p, mut n, mut uv, mut idx) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for r in 0..=rings {
        let theta = std::f32::consts::PI * r as f32 / rings as f32;
        for s in 0..=segments {
            let phi = std::f32::consts::TAU * s as f32 / segments as f32;
            let v = [
                theta.sin() * phi.cos(),
                theta.cos(),
                -theta.sin() * phi.sin(),
            ];
            p.extend(v);
            n.extend(v);
            uv.extend([s as f32 / segments as f32, r as f32 / rings as f32]);
        }
    }
    let w = segments + 1;
    for r in 0..rings {
        for s in 0..segments {
            let (a, b) = (r * w + s, (r + 1) * w + s);
            idx.extend([a, b, a + 1, a + 1, b, b + 1]);
        }
    }
    (p, n, uv, idx)
}

fn main() {
    let mut bin: Vec<u8> = Vec::new();
    let mut views = Vec::new();
    let mut accessors = Vec::new();
    let mut add = |bytes: Vec<u8>, accessor: serde_json::Value| {
        while !bin.len().is_multiple_of(4) {
            bin.push(0);
        }
        views.push(json!({"buffer": 0, "byteOffset": bin.len(), "byteLength": bytes.len()}));
        bin.extend(bytes);
        let mut a = accessor;
        a["bufferView"] = json!(views.len() - 1);
        accessors.push(a);
        accessors.len() - 1
    };
    let f = |v: &[f32]| v.iter().flat_map(|x| x.to_le_bytes()).collect::<Vec<u8>>();
    let (p, n, uv, idx) = sphere(24, 48);
    let count = p.len() / 3;
    let pos = add(
        f(&p),
        json!({"componentType": 5126, "count": count, "type": "VEC3",
                                "min": [-1.0, -1.0, -1.0], "max": [1.0, 1.0, 1.0]}),
    );
    let nrm = add(
        f(&n),
        json!({"componentType": 5126, "count": count, "type": "VEC3"}),
    );
    let tex = add(
        f(&uv),
        json!({"componentType": 5126, "count": count, "type": "VEC2"}),
    );
    let ind = add(
        idx.iter().flat_map(|i| (*i as u16).to_le_bytes()).collect(),
        json!({"componentType": 5123, "count": idx.len(), "type": "SCALAR"}),
    );
    // The floor: a square of side 8 at y = −1 facing up, uvs over [0, 1]².
    let fp = add(
        f(&[-4., -1., 4., 4., -1., 4., 4., -1., -4., -4., -1., -4.]),
        json!({"componentType": 5126, "count": 4, "type": "VEC3",
               "min": [-4.0, -1.0, -4.0], "max": [4.0, -1.0, 4.0]}),
    );
    let fn_ = add(
        f(&[0., 1., 0., 0., 1., 0., 0., 1., 0., 0., 1., 0.]),
        json!({"componentType": 5126, "count": 4, "type": "VEC3"}),
    );
    let fuv = add(
        f(&[0., 1., 1., 1., 1., 0., 0., 0.]),
        json!({"componentType": 5126, "count": 4, "type": "VEC2"}),
    );
    let find = add(
        [0u16, 1, 2, 0, 2, 3]
            .iter()
            .flat_map(|i| i.to_le_bytes())
            .collect(),
        json!({"componentType": 5123, "count": 6, "type": "SCALAR"}),
    );
    let checker = image::RgbImage::from_fn(64, 64, |x, y| {
        if (x / 8 + y / 8) % 2 == 0 {
            image::Rgb([200, 200, 190])
        } else {
            image::Rgb([60, 70, 80])
        }
    });
    let mut png = std::io::Cursor::new(Vec::new());
    checker.write_to(&mut png, image::ImageFormat::Png).unwrap();
    let sphere_prim = |material: usize| {
        json!({"attributes": {"POSITION": pos, "NORMAL": nrm, "TEXCOORD_0": tex},
               "indices": ind, "material": material})
    };
    let half = std::f32::consts::FRAC_1_SQRT_2;
    let doc = json!({
        "asset": {"version": "2.0", "generator": "candela make_gltf_example"},
        "extensionsUsed": ["KHR_lights_punctual", "KHR_materials_transmission",
                           "KHR_materials_ior", "KHR_texture_transform"],
        "scene": 0,
        "scenes": [{"nodes": [0, 1, 2, 3, 4, 5, 6]}],
        "nodes": [
            {"name": "gold", "mesh": 0, "translation": [-2.1, 0.0, 0.0]},
            {"name": "red", "mesh": 1},
            {"name": "glass", "mesh": 2, "translation": [2.1, 0.0, 0.0]},
            {"name": "floor", "mesh": 3},
            {"name": "spot", "translation": [0.0, 5.0, 1.0],
             "rotation": [-half, 0.0, 0.0, half],
             "extensions": {"KHR_lights_punctual": {"light": 0}}},
            {"name": "fill", "translation": [-3.0, 2.5, 4.0],
             "extensions": {"KHR_lights_punctual": {"light": 1}}},
            {"name": "camera", "camera": 0, "translation": [0.0, 1.6, 7.5],
             "rotation": [-0.1045, 0.0, 0.0, 0.9945]}
        ],
        "meshes": [
            {"primitives": [sphere_prim(0)]},
            {"primitives": [sphere_prim(1)]},
            {"primitives": [sphere_prim(2)]},
            {"primitives": [{"attributes": {"POSITION": fp, "NORMAL": fn_, "TEXCOORD_0": fuv},
                             "indices": find, "material": 3}]}
        ],
        "materials": [
            {"name": "gold", "pbrMetallicRoughness": {
                "baseColorFactor": [1.0, 0.766, 0.336, 1.0], "metallicFactor": 1.0,
                "roughnessFactor": 0.35}},
            {"name": "red", "pbrMetallicRoughness": {
                "baseColorFactor": [0.7, 0.05, 0.04, 1.0], "metallicFactor": 0.0,
                "roughnessFactor": 0.25}},
            {"name": "glass", "pbrMetallicRoughness": {"roughnessFactor": 0.0,
                "metallicFactor": 0.0},
             "extensions": {"KHR_materials_transmission": {"transmissionFactor": 1.0},
                            "KHR_materials_ior": {"ior": 1.5}}},
            {"name": "floor", "pbrMetallicRoughness": {
                "baseColorTexture": {"index": 0, "extensions": {
                    "KHR_texture_transform": {"scale": [2.0, 2.0]}}},
                "metallicFactor": 0.0, "roughnessFactor": 0.8}}
        ],
        "textures": [{"source": 0, "sampler": 0}],
        "samplers": [{"magFilter": 9729, "wrapS": 10497, "wrapT": 10497}],
        "images": [{"uri": format!("data:image/png;base64,{}", base64::encode(png.get_ref()))}],
        "extensions": {"KHR_lights_punctual": {"lights": [
            {"name": "key", "type": "spot", "color": [1.0, 0.95, 0.85], "intensity": 25000.0,
             "spot": {"innerConeAngle": 0.45, "outerConeAngle": 0.75}},
            {"name": "fill", "type": "point", "color": [0.6, 0.75, 1.0], "intensity": 4000.0}
        ]}},
        "cameras": [{"type": "perspective", "perspective": {
            "yfov": 0.6, "aspectRatio": 1.6, "znear": 0.1}}],
        "bufferViews": views,
        "accessors": accessors,
        "buffers": [{"byteLength": bin.len(),
                     "uri": format!("data:application/octet-stream;base64,{}", base64::encode(&bin))}]
    });
    let out = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../scenes/gltf/spheres.gltf"
    );
    std::fs::create_dir_all(std::path::Path::new(out).parent().unwrap()).unwrap();
    std::fs::write(out, serde_json::to_string_pretty(&doc).unwrap()).unwrap();
    println!("wrote {out}");
}
