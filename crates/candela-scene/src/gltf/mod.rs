//! glTF 2.0 import (`.gltf` with external or embedded buffers, `.glb`) through the `gltf`
//! crate: a scene's node hierarchy becomes shapes, materials, punctual lights and a
//! camera of a [`SceneDesc`]. What is read and how is documented in the README's glTF
//! section; in short:
//!
//! - [`mesh`]: triangles, strips and fans, indexed or not; missing normals give flat
//!   shading (the rule glTF 2.0 §3.7.2.1 prescribes); COLOR_0 multiplies the base
//!   colour; TANGENT frames normal maps, or ∂p/∂u with the uv orientation's sign.
//! - [`material`]: metallic-roughness, normal maps with scale, emission, alpha modes,
//!   KHR_materials_{emissive_strength, ior, transmission}, KHR_texture_transform.
//! - [`light`]: KHR_lights_punctual in candela and lux, converted at 683 lm/W by the build.
//! - [`camera`]: the scene's first perspective camera, or a three-quarter view of the
//!   bounds.
//!
//! Errors are located: JSON syntax errors by `file:line:col`, semantic ones by the JSON
//! path (`file: meshes[2].primitives[0]: …`). [`parse_gltf`] works on bytes in memory.

use std::borrow::Cow;
use std::collections::HashSet;
use std::path::Path;

use candela_core::desc::{EnvironmentDesc, LightDesc, MaterialDesc, SceneDesc, ShapeDesc, Span};
use glam::Mat4;

use crate::{LoadError, LoadOptions, LoadedScene};

pub mod camera;
mod image;
pub mod light;
pub mod material;
pub mod mesh;

/// The extensions Candela reads; any other in `extensionsRequired` is an error, and in
/// `extensionsUsed` a warning.
pub const SUPPORTED_EXTENSIONS: &[&str] = &[
    "KHR_lights_punctual",
    "KHR_materials_emissive_strength",
    "KHR_materials_ior",
    "KHR_materials_transmission",
    "KHR_texture_transform",
];

/// What a glTF scene contributes: shapes placed in the world, their materials, lights,
/// and the first camera if it has one.
#[derive(Clone, Debug, Default)]
pub struct GltfScene {
    pub shapes: Vec<ShapeDesc>,
    pub materials: Vec<MaterialDesc>,
    pub lights: Vec<LightDesc>,
    /// The first camera met in the node hierarchy, with the image aspect it asks for.
    pub camera: Option<(candela_core::desc::CameraDesc, Option<f32>)>,
    pub warnings: Vec<String>,
}

/// The state of one import: the document, its buffers, where errors point.
pub(crate) struct Ctx<'a> {
    pub doc: &'a gltf::Document,
    pub buffers: Vec<gltf::buffer::Data>,
    /// Folder that relative URIs resolve against; `None` for bytes in memory.
    pub base: Option<&'a Path>,
    pub file: String,
    /// Prefix of material names, so that several imports can share one scene.
    pub prefix: String,
    pub warnings: Vec<String>,
    warned: HashSet<String>,
}

impl Ctx<'_> {
    /// An error at a JSON path of this file.
    pub fn error(&self, path: &str, message: impl std::fmt::Display) -> LoadError {
        LoadError::new(self.span(), format!("{path}: {message}"))
    }

    pub fn span(&self) -> Span {
        Span::new(self.file.as_str(), 0, 0)
    }

    /// A warning, given once per distinct text.
    pub fn warn(&mut self, message: impl Into<String>) {
        let message = format!("{}: {}", self.file, message.into());
        if self.warned.insert(message.clone()) {
            self.warnings.push(message);
        }
    }
}

/// Converts the `gltf` crate's error: JSON errors keep their line and column.
fn gltf_error(file: &str, e: gltf::Error) -> LoadError {
    match e {
        gltf::Error::Deserialize(e) => LoadError::new(
            Span::new(file, e.line() as u32, e.column() as u32),
            format!("invalid glTF JSON: {e}"),
        ),
        gltf::Error::Validation(errors) => {
            let list: Vec<String> = errors
                .iter()
                .take(5)
                .map(|(path, e)| format!("{}: {e}", path.as_str()))
                .collect();
            LoadError::new(Span::new(file, 0, 0), list.join("; "))
        }
        gltf::Error::BufferLength {
            buffer,
            expected,
            actual,
        } => LoadError::new(
            Span::new(file, 0, 0),
            format!("buffers[{buffer}]: declares {expected} bytes but has {actual}"),
        ),
        gltf::Error::MissingBlob => LoadError::new(
            Span::new(file, 0, 0),
            "a buffer refers to the GLB binary chunk, which is missing",
        ),
        gltf::Error::ExternalReferenceInSliceImport => LoadError::new(
            Span::new(file, 0, 0),
            "a buffer refers to an external file, which bytes in memory cannot resolve",
        ),
        e => LoadError::new(Span::new(file, 0, 0), format!("cannot read glTF: {e}")),
    }
}

/// Checks what `gltf-json` 1.4's validation indexes without a bounds check (it would
/// panic on a POSITION accessor that does not exist).
fn check_position_indices(file: &str, root: &gltf::json::Root) -> Result<(), LoadError> {
    let positions = gltf::json::validation::Checked::Valid(gltf::Semantic::Positions);
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, prim) in mesh.primitives.iter().enumerate() {
            if let Some(a) = prim.attributes.get(&positions) {
                if a.value() >= root.accessors.len() {
                    return Err(LoadError::new(
                        Span::new(file, 0, 0),
                        format!(
                            "meshes[{m}].primitives[{p}].attributes.POSITION: accessors[{}] \
                             does not exist ({} accessors)",
                            a.value(),
                            root.accessors.len()
                        ),
                    ));
                }
            }
        }
    }
    Ok(())
}

/// An error for the first extension in `required` that Candela does not support.
fn check_required_extensions<'a>(
    file: &str,
    required: impl IntoIterator<Item = &'a str>,
) -> Result<(), LoadError> {
    match required
        .into_iter()
        .find(|ext| !SUPPORTED_EXTENSIONS.contains(ext))
    {
        Some(ext) => Err(LoadError::new(
            Span::new(file, 0, 0),
            format!(
                "requires extension {ext}, which Candela does not support (supported: {})",
                SUPPORTED_EXTENSIONS.join(", ")
            ),
        )),
        None => Ok(()),
    }
}

/// Reads the document (JSON, or GLB with its binary chunk) without validating it. Where
/// `gltf-json` 1.4 cannot deserialize it, scenes without `nodes`, which glTF 2.0 allows
/// (§5.17) but the crate does not, get an empty list and the JSON is read once more;
/// otherwise the first error stands.
fn read_document(name: &str, bytes: &[u8]) -> Result<gltf::Gltf, LoadError> {
    let first = match gltf::Gltf::from_slice_without_validation(bytes) {
        Ok(g) => return Ok(g),
        Err(e @ gltf::Error::Deserialize(_)) => gltf_error(name, e),
        Err(e) => return Err(gltf_error(name, e)),
    };
    let (json, blob) = if bytes.starts_with(b"glTF") {
        let Ok(glb) = gltf::Glb::from_slice(bytes) else {
            return Err(first);
        };
        (glb.json.into_owned(), glb.bin.map(|b| b.into_owned()))
    } else {
        (bytes.to_vec(), None)
    };
    let Ok(mut value) = gltf::json::deserialize::from_slice::<gltf::json::Value>(&json) else {
        return Err(first);
    };
    let mut patched = false;
    for scene in value
        .get_mut("scenes")
        .and_then(|s| s.as_array_mut())
        .into_iter()
        .flatten()
    {
        if let Some(scene) = scene.as_object_mut().filter(|s| !s.contains_key("nodes")) {
            scene.insert("nodes".into(), gltf::json::Value::Array(Vec::new()));
            patched = true;
        }
    }
    if !patched {
        return Err(first);
    }
    let root: gltf::json::Root = gltf::json::deserialize::from_value(value).map_err(|_| first)?;
    Ok(gltf::Gltf {
        document: gltf::Document::from_json_without_validation(root),
        blob,
    })
}

/// Parses a glTF or GLB file held in memory into the shapes, materials, lights and
/// camera of one of its scenes (`options.scene`, else the default, else the first).
/// External files resolve against `base`; `file` names the source in messages. Bytes
/// given owned are freed once the document and its binary chunk are read from them,
/// before the meshes are.
pub fn parse_gltf_scene(
    bytes: Cow<'_, [u8]>,
    file: &Path,
    base: Option<&Path>,
    options: &LoadOptions,
    prefix: &str,
) -> Result<GltfScene, LoadError> {
    let name = file.display().to_string();
    let gltf::Gltf { document, blob } = read_document(&name, &bytes)?;
    drop(bytes);
    check_required_extensions(&name, document.extensions_required())?;
    let mut warnings = Vec::new();
    for ext in document.extensions_used() {
        if !SUPPORTED_EXTENSIONS.contains(&ext) {
            warnings.push(format!(
                "{name}: extension {ext} is not supported and is ignored"
            ));
        }
    }
    check_position_indices(&name, document.as_json())?;
    // Validation resolves every index (out-of-range references are errors here).
    let document =
        gltf::Document::from_json(document.into_json()).map_err(|e| gltf_error(&name, e))?;
    let buffers = gltf::import_buffers(&document, base, blob).map_err(|e| gltf_error(&name, e))?;
    let mut ctx = Ctx {
        doc: &document,
        buffers,
        base,
        file: name,
        prefix: prefix.to_string(),
        warnings,
        warned: HashSet::new(),
    };
    let scene = match options.scene {
        Some(i) => ctx.doc.scenes().nth(i).ok_or_else(|| {
            ctx.error(
                "scenes",
                format!(
                    "scene {i} does not exist ({} scenes)",
                    ctx.doc.scenes().len()
                ),
            )
        })?,
        None => match ctx.doc.default_scene().or_else(|| ctx.doc.scenes().next()) {
            Some(s) => s,
            None => return Err(ctx.error("scenes", "the file has no scene")),
        },
    };
    let mut out = GltfScene::default();
    let mut materials = material::Materials::default();
    let mut meshes = mesh::MeshCache::default();
    let mut stack: Vec<(gltf::Node, Mat4)> = scene.nodes().map(|n| (n, Mat4::IDENTITY)).collect();
    stack.reverse();
    // Nodes form disjoint trees (glTF 2.0 §3.5.3): meeting one twice means a cycle or a
    // shared child, and either would never end or place things twice.
    let mut visited = HashSet::new();
    while let Some((node, parent)) = stack.pop() {
        if !visited.insert(node.index()) {
            return Err(ctx.error(
                &format!("nodes[{}]", node.index()),
                "the node is reached twice: the hierarchy has a cycle or a shared child",
            ));
        }
        let world = parent * Mat4::from_cols_array_2d(&node.transform().matrix());
        if !world.is_finite() {
            return Err(ctx.error(
                &format!("nodes[{}]", node.index()),
                "transform is not finite",
            ));
        }
        if let Some(m) = node.mesh() {
            mesh::place_mesh(&mut ctx, &mut meshes, &mut materials, &mut out, &m, world)?;
        }
        if node.skin().is_some() {
            ctx.warn(format!(
                "nodes[{}]: skinning is ignored (the mesh is drawn in its bind pose)",
                node.index()
            ));
        }
        if let Some(l) = node.light() {
            out.lights.push(light::light(&mut ctx, &l, world)?);
        }
        if let (Some(c), None) = (node.camera(), &out.camera) {
            out.camera = Some(camera::camera(&ctx, &c, world));
        }
        let mut children: Vec<_> = node.children().collect();
        children.reverse();
        for child in children {
            stack.push((child, world));
        }
    }
    out.materials = materials.into_descs();
    out.warnings = ctx.warnings;
    Ok(out)
}

/// Parses a glTF or GLB file in memory into a whole scene: its shapes, lights and camera,
/// an automatic camera where it has none, and a uniform white environment of strength
/// 1 (with a warning) where it has no light at all. The entry point for fuzzing.
pub fn parse_gltf(
    bytes: &[u8],
    file: &Path,
    base: Option<&Path>,
    options: &LoadOptions,
) -> Result<LoadedScene, LoadError> {
    let g = parse_gltf_scene(Cow::Borrowed(bytes), file, base, options, "")?;
    Ok(whole_scene(g, file))
}

/// A glTF scene as a whole scene (see [`parse_gltf`]).
fn whole_scene(g: GltfScene, file: &Path) -> LoadedScene {
    let mut desc = SceneDesc {
        shapes: g.shapes,
        materials: g.materials,
        lights: g.lights,
        ..SceneDesc::default()
    };
    let mut warnings = g.warnings;
    match g.camera {
        Some((camera, aspect)) => {
            desc.camera = camera;
            if let Some(a) = aspect.filter(|a| a.is_finite() && *a > 0.0) {
                let r = &mut desc.render;
                r.height = ((r.width as f32 / a).round() as u32).max(1);
            }
        }
        None => desc.camera = camera::framing_camera(&desc.shapes, desc.camera.fov_y_deg),
    }
    light_if_unlit(&mut desc, file, &mut warnings);
    LoadedScene { desc, warnings }
}

/// Gives a scene without lights or emitting shapes (a model file of `file`) a uniform
/// white environment of strength 1, and says so.
pub(crate) fn light_if_unlit(desc: &mut SceneDesc, file: &Path, warnings: &mut Vec<String>) {
    let emits = desc.shapes.iter().any(|s| s.emission.is_some());
    if desc.lights.is_empty() && !emits && desc.environment.is_none() {
        warnings.push(format!(
            "{}: no lights: lit by a uniform white environment of strength 1 (--env chooses \
             another)",
            file.display()
        ));
        desc.environment = Some(EnvironmentDesc {
            span: Span::new(file.display().to_string(), 0, 0),
            ..EnvironmentDesc::default()
        });
    }
}

/// Loads a `.gltf` or `.glb` file (see [`parse_gltf`]).
pub fn load_gltf(path: &Path, options: &LoadOptions) -> Result<LoadedScene, LoadError> {
    let bytes = std::fs::read(path).map_err(|e| {
        LoadError::new(
            Span::new(path.display().to_string(), 0, 0),
            format!("cannot read glTF file: {e}"),
        )
    })?;
    let base = Some(path.parent().unwrap_or(Path::new(".")));
    let g = parse_gltf_scene(Cow::Owned(bytes), path, base, options, "")?;
    Ok(whole_scene(g, path))
}
