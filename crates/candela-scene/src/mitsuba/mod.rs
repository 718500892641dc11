//! Mitsuba 3 XML scenes (a subset; see `docs/mitsuba.md`).
//!
//! Three stages, as in Mitsuba's own loader: [`parse`] turns the XML (with `<default>`,
//! `$param`, `<include>`) into a node tree with source spans; the mapping modules turn
//! each plugin into Candela's description; whatever a plugin leaves unread is an error
//! naming it (a warning under `lenient`), so nothing is silently dropped.

mod aov;
mod bsdfs;
mod emitters;
mod media;
mod parse;
mod sensor;
pub mod serialized;
mod shapes;
mod spectra;
mod textures;
mod transform;

use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;

use candela_core::desc::{MeshDesc, SceneDesc, ShapeDesc, TextureDesc};
use glam::Vec3;

use crate::{LoadError, LoadOptions, LoadedScene};
use parse::Node;

pub use sensor::candela_max_depth;

/// Loads a Mitsuba 3 XML scene.
pub fn load_mitsuba(path: &Path, options: &LoadOptions) -> Result<LoadedScene, LoadError> {
    let root = parse::parse_file(path, &options.defines)?;
    map_scene(root, path, options)
}

/// Parses a Mitsuba 3 XML scene from its text; `path` names it in errors, and files it
/// refers to (meshes, textures, includes) are looked up beside it.
pub fn parse_mitsuba(
    text: &str,
    path: &Path,
    options: &LoadOptions,
) -> Result<LoadedScene, LoadError> {
    let root = parse::parse_str(text, path, &options.defines)?;
    map_scene(root, path, options)
}

/// Maps a parsed `<scene>` to Candela's description.
fn map_scene(root: Node, path: &Path, options: &LoadOptions) -> Result<LoadedScene, LoadError> {
    let mut ctx = Ctx {
        lenient: options.lenient,
        base: path.parent().unwrap_or(Path::new("")).to_path_buf(),
        warnings: Vec::new(),
        bsdf_ids: HashMap::new(),
        texture_ids: HashMap::new(),
        shape_groups: HashMap::new(),
        mesh_files: HashMap::new(),
        medium_ids: std::collections::HashSet::new(),
        desc: SceneDesc::default(),
    };
    // Mitsuba's default integrator is `path` with unlimited depth.
    ctx.desc.render.max_depth = candela_max_depth(-1).expect("-1 is valid");
    // Named textures, then named BSDFs, so that shapes may refer to them wherever they
    // are defined.
    for c in root.children.iter().filter(|c| c.tag == "texture") {
        c.used.set(true);
        let Some(id) = c.attr("id") else {
            return Err(c.error("a top-level <texture> needs an id"));
        };
        let tex = textures::texture(&mut ctx, c)?;
        if ctx.texture_ids.insert(id.to_string(), tex).is_some() {
            return Err(c.error(format!("id \"{id}\" is used twice")));
        }
    }
    // Named BSDFs first, so that shapes may refer to them wherever they are defined.
    for c in root.children.iter().filter(|c| c.tag == "bsdf") {
        c.used.set(true);
        let name = bsdfs::material(&mut ctx, c)?;
        if let Some(id) = c.attr("id") {
            ctx.bsdf_ids.insert(id.to_string(), name);
        }
    }
    // Named media, before the shapes and sensor that refer to them.
    for c in root.children.iter().filter(|c| c.tag == "medium") {
        let name = media::medium(&mut ctx, c)?;
        ctx.medium_ids.insert(name);
    }
    // Shape groups next, so that instances may come before or after their group.
    for c in root
        .children
        .iter()
        .filter(|c| c.tag == "shape" && c.kind() == "shapegroup")
    {
        shapes::shape_group(&mut ctx, c)?;
    }
    for c in &root.children {
        match c.tag.as_str() {
            "bsdf" | "texture" | "medium" => {}
            "shape" => shapes::shape(&mut ctx, c)?,
            "emitter" => emitters::emitter(&mut ctx, c)?,
            "sensor" => sensor::sensor(&mut ctx, c)?,
            "integrator" => sensor::integrator(&mut ctx, c)?,
            _ => ctx.unsupported(c, format!("<{}> is not supported", describe(c)))?,
        }
        c.used.set(true);
    }
    Ok(LoadedScene {
        desc: ctx.desc,
        warnings: ctx.warnings,
    })
}

/// A mesh file as a shape reads it: the path, the mesh's index in a serialized file (0
/// for the others), `face_normals` and whether the uvs' v is flipped.
pub(crate) type MeshKey = (std::path::PathBuf, u32, bool, bool);

/// What the mapping builds up, and how strict it is.
pub(crate) struct Ctx {
    pub lenient: bool,
    /// Folder of the scene file: relative file names start there.
    pub base: std::path::PathBuf,
    pub warnings: Vec<String>,
    /// Material name of each BSDF `id`.
    pub bsdf_ids: HashMap<String, String>,
    /// Each top-level texture by its `id`.
    pub texture_ids: HashMap<String, TextureDesc>,
    /// The shapes of each `shapegroup` by its `id`, in the group's object space.
    pub shape_groups: HashMap<String, Vec<ShapeDesc>>,
    /// Meshes loaded so far.
    pub mesh_files: HashMap<MeshKey, Arc<MeshDesc>>,
    /// Names of the top-level media (their ids).
    pub medium_ids: std::collections::HashSet<String>,
    pub desc: SceneDesc,
}

impl Ctx {
    /// Something outside the subset: an error, or under `lenient` a warning (and the
    /// caller skips it or uses the closest thing Candela has).
    pub fn unsupported(&mut self, node: &Node, message: String) -> Result<(), LoadError> {
        mark_all_used(node);
        let e = node.error(message);
        if self.lenient {
            self.warnings.push(format!("{e} (skipped: --lenient)"));
            Ok(())
        } else {
            Err(e)
        }
    }

    /// A difference Candela's image will show, always only a warning.
    pub fn warn(&mut self, node: &Node, message: impl Into<String>) {
        self.warnings.push(node.error(message).to_string());
    }

    /// Reports every child of a plugin that its mapping did not read.
    pub fn check_unused(&mut self, node: &Node) -> Result<(), LoadError> {
        for c in node.children.iter().filter(|c| !c.used.get()) {
            let what = match c.attr("name") {
                Some(n) => format!("<{} name=\"{n}\">", c.tag),
                None => format!("<{}>", describe(c)),
            };
            self.unsupported(c, format!("{what} is not supported in {}", describe(node)))?;
        }
        Ok(())
    }

    /// A texturable property: a nested `<texture>`, a `<ref>` to a top-level one, or a
    /// colour; `default` when it is absent.
    pub fn texture(
        &mut self,
        node: &Node,
        name: &str,
        default: Vec3,
    ) -> Result<TextureDesc, LoadError> {
        if let Some(r) = node
            .children
            .iter()
            .find(|c| c.tag == "ref" && c.name() == name)
        {
            r.used.set(true);
            let id = r.req("id")?;
            return self
                .texture_ids
                .get(id)
                .cloned()
                .ok_or_else(|| r.error(format!("no texture has the id \"{id}\"")));
        }
        match node.prop(name) {
            Some(t) if t.tag == "texture" => textures::texture(self, t),
            _ => Ok(TextureDesc::Constant(node.color(name)?.unwrap_or(default))),
        }
    }

    /// A unique material name for an unnamed BSDF.
    pub fn fresh_name(&self, node: &Node) -> String {
        format!("{}@{}:{}", node.kind(), node.span.line, node.span.col)
    }
}

fn mark_all_used(node: &Node) {
    node.used.set(true);
    node.children.iter().for_each(mark_all_used);
}

/// `shape type="obj"` style: the element with its plugin type.
pub(crate) fn describe(n: &Node) -> String {
    match n.attr("type") {
        Some(t) => format!("{} type=\"{t}\"", n.tag),
        None => n.tag.clone(),
    }
}
