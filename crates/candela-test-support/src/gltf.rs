//! Shared by the glTF tests: a small GLB writer (JSON + one binary buffer), so tests make
//! their own files with exactly the features they check, and a JSON reader for GLB.

use serde_json::{json, Value};

/// A glTF document under construction; [`Glb::bytes`] packs it as a `.glb`.
pub struct Glb {
    pub json: Value,
    pub bin: Vec<u8>,
}

impl Default for Glb {
    fn default() -> Self {
        Glb::new()
    }
}

impl Glb {
    pub fn new() -> Glb {
        Glb {
            json: json!({
                "asset": {"version": "2.0"},
                "buffers": [], "bufferViews": [], "accessors": [],
                "meshes": [], "nodes": [], "scenes": [{"nodes": []}], "scene": 0,
                "materials": [],
            }),
            bin: Vec::new(),
        }
    }

    fn push(&mut self, key: &str, v: Value) -> usize {
        let a = self.json[key].as_array_mut().unwrap();
        a.push(v);
        a.len() - 1
    }

    /// Appends bytes as a buffer view (4-byte aligned) and returns its index.
    pub fn view(&mut self, bytes: &[u8]) -> usize {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        let offset = self.bin.len();
        self.bin.extend_from_slice(bytes);
        self.push(
            "bufferViews",
            json!({"buffer": 0, "byteOffset": offset, "byteLength": bytes.len()}),
        )
    }

    /// A float accessor of `n`-component elements (`ty` "VEC2", "VEC3", ...), with min/max.
    pub fn floats(&mut self, data: &[f32], n: usize, ty: &str) -> usize {
        let bytes: Vec<u8> = data.iter().flat_map(|f| f.to_le_bytes()).collect();
        let view = self.view(&bytes);
        let count = data.len() / n;
        let (mut min, mut max) = (vec![f32::INFINITY; n], vec![f32::NEG_INFINITY; n]);
        for e in data.chunks(n) {
            for i in 0..n {
                min[i] = min[i].min(e[i]);
                max[i] = max[i].max(e[i]);
            }
        }
        self.push(
            "accessors",
            json!({"bufferView": view, "componentType": 5126, "count": count, "type": ty,
                   "min": min, "max": max}),
        )
    }

    /// An unsigned-int (u32) index accessor.
    pub fn indices(&mut self, data: &[u32]) -> usize {
        let bytes: Vec<u8> = data.iter().flat_map(|i| i.to_le_bytes()).collect();
        let view = self.view(&bytes);
        self.push(
            "accessors",
            json!({"bufferView": view, "componentType": 5125, "count": data.len(),
                   "type": "SCALAR"}),
        )
    }

    /// A mesh of the given primitives; returns its index.
    pub fn mesh(&mut self, primitives: Vec<Value>) -> usize {
        self.push("meshes", json!({ "primitives": primitives }))
    }

    pub fn material(&mut self, m: Value) -> usize {
        self.push("materials", m)
    }

    /// A node; `root` puts it in scene 0.
    pub fn node(&mut self, n: Value, root: bool) -> usize {
        let i = self.push("nodes", n);
        if root {
            self.json["scenes"][0]["nodes"]
                .as_array_mut()
                .unwrap()
                .push(json!(i));
        }
        i
    }

    /// An embedded image (PNG bytes) with a texture using `sampler` (None: default).
    pub fn texture(&mut self, png: &[u8], sampler: Option<Value>) -> usize {
        let view = self.view(png);
        if self.json.get("images").is_none() {
            self.json["images"] = json!([]);
            self.json["textures"] = json!([]);
            self.json["samplers"] = json!([]);
        }
        let image = self.push(
            "images",
            json!({"bufferView": view, "mimeType": "image/png"}),
        );
        let mut t = json!({ "source": image });
        if let Some(s) = sampler {
            t["sampler"] = json!(self.push("samplers", s));
        }
        self.push("textures", t)
    }

    /// A unit quad in z = 0 (normal +z, uvs spanning [0, 1]²) as a primitive of `material`.
    pub fn quad(&mut self, material: usize) -> Value {
        let pos = self.floats(
            &[-1., -1., 0., 1., -1., 0., 1., 1., 0., -1., 1., 0.],
            3,
            "VEC3",
        );
        let nrm = self.floats(&[0., 0., 1., 0., 0., 1., 0., 0., 1., 0., 0., 1.], 3, "VEC3");
        // glTF v runs down the image: v = 0 at the top edge (y = +1).
        let uv = self.floats(&[0., 1., 1., 1., 1., 0., 0., 0.], 2, "VEC2");
        let idx = self.indices(&[0, 1, 2, 0, 2, 3]);
        json!({"attributes": {"POSITION": pos, "NORMAL": nrm, "TEXCOORD_0": uv},
               "indices": idx, "material": material})
    }

    /// A scene of one [`Glb::quad`] with a default material, its mesh in a root node.
    /// Accessors: 0 POSITION, 1 NORMAL, 2 TEXCOORD_0, 3 indices.
    pub fn one_quad() -> Glb {
        let mut g = Glb::new();
        let q = g.quad(0);
        g.material(json!({}));
        let mesh = g.mesh(vec![q]);
        g.node(json!({ "mesh": mesh }), true);
        g
    }

    /// The `.glb` bytes: header, JSON chunk, BIN chunk.
    pub fn bytes(&self) -> Vec<u8> {
        let mut json = self.json.clone();
        let mut bin = self.bin.clone();
        while !bin.len().is_multiple_of(4) {
            bin.push(0);
        }
        json["buffers"] = json!([{ "byteLength": self.bin.len() }]);
        let mut text = serde_json::to_vec(&json).unwrap();
        while !text.len().is_multiple_of(4) {
            text.push(b' ');
        }
        let total = 12 + 8 + text.len() + 8 + bin.len();
        let mut out = Vec::with_capacity(total);
        out.extend_from_slice(b"glTF");
        out.extend_from_slice(&2u32.to_le_bytes());
        out.extend_from_slice(&(total as u32).to_le_bytes());
        out.extend_from_slice(&(text.len() as u32).to_le_bytes());
        out.extend_from_slice(b"JSON");
        out.extend_from_slice(&text);
        out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
        out.extend_from_slice(b"BIN\0");
        out.extend_from_slice(&bin);
        out
    }
}

/// A PNG of `w`×`h` RGBA pixels from a function of (x, y).
pub fn png(w: u32, h: u32, f: impl Fn(u32, u32) -> [u8; 4]) -> Vec<u8> {
    let img = image::RgbaImage::from_fn(w, h, |x, y| image::Rgba(f(x, y)));
    let mut out = std::io::Cursor::new(Vec::new());
    img.write_to(&mut out, image::ImageFormat::Png).unwrap();
    out.into_inner()
}

/// The JSON of a `.gltf` or `.glb` file.
pub fn read_json(bytes: &[u8]) -> Value {
    if bytes.starts_with(b"glTF") {
        let len = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
        serde_json::from_slice(&bytes[20..20 + len]).unwrap()
    } else {
        serde_json::from_slice(bytes).unwrap()
    }
}
