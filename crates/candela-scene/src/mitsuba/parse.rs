//! Mitsuba XML to a neutral node tree: `<default>` and `$param` substitution, `<include>`
//! spliced in, every element with its source span. Mapping to Candela happens later, on
//! this tree (Mitsuba's own loader has the same parse → check → build stages).

use std::cell::Cell;
use std::collections::HashMap;
use std::path::Path;

use candela_core::desc::Span;
use glam::Vec3;

use super::spectra::{spectrum_to_rgb, SpectrumUse};
use crate::{LoadError, Source};

/// How deep `<include>`s may nest before we call it a cycle.
const MAX_INCLUDE_DEPTH: usize = 16;

/// How deep elements may nest. Mitsuba scenes nest a handful of levels (a BSDF in a
/// BSDF in a shape); the tree is converted recursively, so without a cap a file of a
/// few hundred kilobytes of `<a><a><a>…` would overflow the stack.
const MAX_NESTING: usize = 128;

/// One XML element after substitution: a plugin (`shape`, `bsdf`, …), a property
/// (`float`, `rgb`, …), a `transform` step, or a `ref`.
#[derive(Debug)]
pub(crate) struct Node {
    pub tag: String,
    pub attrs: Vec<(String, String)>,
    pub children: Vec<Node>,
    pub span: Span,
    /// Set when a plugin's mapping reads this property; what is left unread is reported.
    pub used: Cell<bool>,
}

impl Node {
    pub fn attr(&self, name: &str) -> Option<&str> {
        self.attrs
            .iter()
            .find(|(k, _)| k == name)
            .map(|(_, v)| v.as_str())
    }

    /// An attribute that must be there.
    pub fn req(&self, name: &str) -> Result<&str, LoadError> {
        self.attr(name)
            .ok_or_else(|| self.error(format!("<{}> lacks the attribute \"{name}\"", self.tag)))
    }

    /// The plugin type (`type="…"`).
    pub fn kind(&self) -> &str {
        self.attr("type").unwrap_or("")
    }

    /// The property name (`name="…"`).
    pub fn name(&self) -> &str {
        self.attr("name").unwrap_or("")
    }

    pub fn error(&self, message: impl Into<String>) -> LoadError {
        LoadError::new(self.span.clone(), message)
    }

    /// The child property called `name`, marked as used.
    pub fn prop(&self, name: &str) -> Option<&Node> {
        let n = self
            .children
            .iter()
            .find(|c| c.name() == name && is_property(&c.tag))?;
        n.used.set(true);
        Some(n)
    }

    /// Whether the property `name` is a texture, nested or by `<ref>` (not a colour).
    pub fn is_texture(&self, name: &str) -> bool {
        self.children
            .iter()
            .any(|c| c.name() == name && matches!(c.tag.as_str(), "texture" | "ref"))
    }

    /// Child plugins with tag `tag` (`bsdf`, `emitter`, …), marked as used.
    pub fn plugins<'a>(&'a self, tag: &'a str) -> impl Iterator<Item = &'a Node> + 'a {
        self.children
            .iter()
            .filter(move |c| c.tag == tag)
            .inspect(|c| c.used.set(true))
    }

    pub fn float(&self, name: &str) -> Result<Option<f32>, LoadError> {
        self.prop(name)
            .map(|p| p.typed(&["float", "integer"])?.parse_f32(p.req("value")?))
            .transpose()
    }

    pub fn integer(&self, name: &str) -> Result<Option<i64>, LoadError> {
        self.prop(name)
            .map(|p| {
                let v = p.typed(&["integer"])?.req("value")?;
                v.trim()
                    .parse::<i64>()
                    .map_err(|_| p.error(format!("\"{v}\" is not an integer")))
            })
            .transpose()
    }

    pub fn boolean(&self, name: &str) -> Result<Option<bool>, LoadError> {
        self.prop(name)
            .map(|p| match p.typed(&["boolean"])?.req("value")?.trim() {
                "true" => Ok(true),
                "false" => Ok(false),
                v => Err(p.error(format!("\"{v}\" is not a boolean (true or false)"))),
            })
            .transpose()
    }

    pub fn string(&self, name: &str) -> Result<Option<&str>, LoadError> {
        self.prop(name)
            .map(|p| p.typed(&["string"])?.req("value"))
            .transpose()
    }

    /// A colour: `rgb`, a `spectrum` (a constant, or wavelength:value pairs reduced as
    /// Mitsuba's RGB variants do: see [`spectra`](super::spectra)), or a `float` (grey).
    /// A conductor's `eta` and `k` are unbounded; other colours are reflectances.
    pub fn color(&self, name: &str) -> Result<Option<Vec3>, LoadError> {
        let use_ = match name {
            "eta" | "k" | "sigma_t" => SpectrumUse::Unbounded,
            _ => SpectrumUse::Reflectance,
        };
        self.colour_as(name, use_)
    }

    /// An emitter's colour (`radiance`, `intensity`, `irradiance`): as [`Node::color`],
    /// except that a spectrum is read as an illuminant: a constant `<spectrum value="v">`
    /// is an equal-energy spectrum of v, which Mitsuba's RGB variants turn into
    /// v·[`EQUAL_ENERGY_RGB`] (a BSDF's constant spectrum stays v in every channel), and
    /// wavelength:value pairs are reduced without the D65 weighting.
    pub fn illuminant(&self, name: &str) -> Result<Option<Vec3>, LoadError> {
        self.colour_as(name, SpectrumUse::Emission)
    }

    fn colour_as(&self, name: &str, use_: SpectrumUse) -> Result<Option<Vec3>, LoadError> {
        let Some(p) = self.prop(name) else {
            return Ok(None);
        };
        match p.tag.as_str() {
            "float" => Ok(Some(Vec3::splat(p.parse_f32(p.req("value")?)?))),
            "rgb" => p.parse_vec3(p.req("value")?, true).map(Some),
            "spectrum" => {
                if let Some(t) = p.attr("type") {
                    // Mitsuba 3.9.1's RGB variants refuse `blackbody` as well ("Not
                    // implemented for non-spectral modes").
                    return Err(p.error(format!(
                        "a <spectrum type=\"{t}\"> is not supported (Candela renders RGB); \
                         give the colour as <rgb>"
                    )));
                }
                if let Some(file) = p.attr("filename") {
                    return p
                        .spectrum_file(file)
                        .map(|pairs| Some(spectrum_to_rgb(&pairs, use_)));
                }
                let v = p.req("value")?;
                if v.contains(':') {
                    return p
                        .spectrum_pairs(v)
                        .map(|pairs| Some(spectrum_to_rgb(&pairs, use_)));
                }
                let c = Vec3::splat(p.parse_f32(v)?);
                Ok(Some(match use_ {
                    SpectrumUse::Emission => c * EQUAL_ENERGY_RGB,
                    SpectrumUse::Reflectance | SpectrumUse::Unbounded => c,
                }))
            }
            "texture" => Err(p.error(format!(
                "\"{name}\" must be a constant colour here, not a <texture>"
            ))),
            other => Err(p.error(format!("\"{name}\" must be a colour, not <{other}>"))),
        }
    }

    /// A spectrum file (Mitsuba's `.spd`: a `λ v` pair a line, `#` comments), beside the
    /// scene file that names it.
    fn spectrum_file(&self, file: &str) -> Result<Vec<(f64, f64)>, LoadError> {
        let dir = Path::new(&*self.span.file)
            .parent()
            .unwrap_or(Path::new(""));
        let path = dir.join(file);
        let text = std::fs::read_to_string(&path)
            .map_err(|e| self.error(format!("cannot read \"{}\": {e}", path.display())))?;
        let pairs: Vec<String> = text
            .lines()
            .map(str::trim)
            .filter(|l| !l.is_empty() && !l.starts_with('#'))
            .map(|l| l.split_whitespace().collect::<Vec<_>>().join(":"))
            .collect();
        self.spectrum_pairs(&pairs.join(", "))
            .map_err(|e| self.error(format!("in \"{}\": {}", path.display(), e.message)))
    }

    /// `λ:v` pairs separated by commas and/or spaces, at least two, λ rising strictly.
    fn spectrum_pairs(&self, v: &str) -> Result<Vec<(f64, f64)>, LoadError> {
        let pairs = v
            .split(|c: char| c == ',' || c.is_whitespace())
            .filter(|s| !s.is_empty())
            .map(|pair| match pair.split_once(':') {
                Some((nm, value)) => {
                    Ok((self.parse_f32(nm)? as f64, self.parse_f32(value)? as f64))
                }
                None => Err(self.error(format!("\"{pair}\" is not a wavelength:value pair"))),
            })
            .collect::<Result<Vec<_>, _>>()?;
        if pairs.len() < 2 {
            return Err(self.error("a spectrum needs at least two wavelength:value pairs"));
        }
        if pairs.windows(2).any(|w| w[0].0 >= w[1].0) {
            return Err(self.error("a spectrum's wavelengths must rise from pair to pair"));
        }
        Ok(pairs)
    }

    /// A `point` or `vector`: `x`/`y`/`z` attributes (missing ones are 0) or `value`.
    pub fn point(&self, name: &str) -> Result<Option<Vec3>, LoadError> {
        self.prop(name)
            .map(|p| p.typed(&["point", "vector"])?.xyz(0.0))
            .transpose()
    }

    pub fn typed(&self, tags: &[&str]) -> Result<&Node, LoadError> {
        if tags.contains(&self.tag.as_str()) {
            Ok(self)
        } else {
            Err(self.error(format!(
                "\"{}\" must be <{}>, not <{}>",
                self.name(),
                tags.join("> or <"),
                self.tag
            )))
        }
    }

    /// A vector from `value="x, y, z"` or from `x`, `y`, `z` attributes defaulting to
    /// `missing`.
    pub fn xyz(&self, missing: f32) -> Result<Vec3, LoadError> {
        if let Some(v) = self.attr("value") {
            return self.parse_vec3(v, false);
        }
        let c = |a: &str| self.attr(a).map_or(Ok(missing), |v| self.parse_f32(v));
        Ok(Vec3::new(c("x")?, c("y")?, c("z")?))
    }

    pub fn parse_f32(&self, v: &str) -> Result<f32, LoadError> {
        match v.trim().parse::<f32>() {
            Ok(x) if x.is_finite() => Ok(x),
            _ => Err(self.error(format!("\"{v}\" is not a finite number"))),
        }
    }

    /// Numbers separated by commas and/or spaces.
    pub fn parse_list(&self, v: &str) -> Result<Vec<f32>, LoadError> {
        v.split(|c: char| c == ',' || c.is_whitespace())
            .filter(|s| !s.is_empty())
            .map(|s| self.parse_f32(s))
            .collect()
    }

    /// Three numbers; with `splat`, one number stands for all three.
    pub fn parse_vec3(&self, v: &str, splat: bool) -> Result<Vec3, LoadError> {
        match *self.parse_list(v)?.as_slice() {
            [x] if splat => Ok(Vec3::splat(x)),
            [x, y, z] => Ok(Vec3::new(x, y, z)),
            _ => Err(self.error(format!("\"{v}\" must be three numbers"))),
        }
    }
}

/// Mitsuba's camelCase to snake_case for upgraded scenes, matching what Mitsuba 3.9.1
/// makes of these names: `toWorld` → `to_world`, `intIOR` → `int_ior`, `fooBAR` →
/// `foo_bar`, `foo2Bar` and a leading capital unchanged (`FooBar` → `Foo_bar`).
pub(crate) fn snake_case(name: &str) -> String {
    let mut out = String::with_capacity(name.len() + 4);
    let (mut prev_lower, mut in_run) = (false, false);
    for c in name.chars() {
        if c.is_ascii_uppercase() {
            if prev_lower {
                out.push('_');
                in_run = true;
            }
            out.push(if in_run { c.to_ascii_lowercase() } else { c });
            prev_lower = false;
        } else {
            out.push(c);
            prev_lower = c.is_ascii_lowercase();
            in_run = false;
        }
    }
    out
}

/// Linear Rec.709 RGB of the equal-energy spectrum of value 1 as Mitsuba 3.9.1's RGB
/// variants compute it: `mi.traverse(mi.load_string('<emitter version="3.0.0"
/// type="point"><spectrum name="intensity" value="1"/></emitter>'))['intensity.value']`.
pub(crate) const EQUAL_ENERGY_RGB: Vec3 = Vec3::new(1.20479, 0.948291, 0.908916);

/// Elements that are properties of the plugin they sit in.
pub(crate) fn is_property(tag: &str) -> bool {
    matches!(
        tag,
        "float"
            | "integer"
            | "boolean"
            | "string"
            | "rgb"
            | "spectrum"
            | "point"
            | "vector"
            | "transform"
            | "texture"
    )
}

/// Parses a scene file (and what it includes) into its `<scene>` node. `defines` are the
/// `-D name=value` parameters, which take precedence over `<default>`s.
pub(crate) fn parse_file(path: &Path, defines: &[(String, String)]) -> Result<Node, LoadError> {
    let span = Span::new(path.display().to_string(), 1, 1);
    let text = std::fs::read_to_string(path)
        .map_err(|e| LoadError::new(span, format!("cannot read scene file: {e}")))?;
    parse_str(&text, path, defines)
}

/// Parses a scene's text into its `<scene>` node; `path` names it in errors and is where
/// `<include>`d files are looked up.
pub(crate) fn parse_str(
    text: &str,
    path: &Path,
    defines: &[(String, String)],
) -> Result<Node, LoadError> {
    let mut p = Parser {
        params: defines.iter().cloned().collect(),
    };
    p.parse_text(path, text, 0)
}

struct Parser {
    /// `-D` parameters, then the `<default>`s met so far.
    params: HashMap<String, String>,
}

impl Parser {
    fn parse_text(&mut self, path: &Path, text: &str, depth: usize) -> Result<Node, LoadError> {
        let src = Source::new(path, text);
        let doc = roxmltree::Document::parse(text).map_err(|e| {
            let pos = e.pos();
            LoadError::new(
                Span::new(src.file.clone(), pos.row, pos.col),
                // roxmltree quotes the offending character, which may be a newline.
                format!("XML: {}", crate::escape_control(&e.to_string())),
            )
        })?;
        let root = doc.root_element();
        if root.tag_name().name() != "scene" {
            return Err(src.error(
                root.range().start,
                format!(
                    "the root element must be <scene>, not <{}>",
                    root.tag_name().name()
                ),
            ));
        }
        // Mitsuba 3 reads scenes of version 0.x and 1.x (Mitsuba 0.6 syntax) by renaming
        // their camelCase property names (`toWorld`, `intIOR`, `sampleCount`) to
        // snake_case, as its parser's `upgrade_tree` does.
        let mut upgrade = false;
        if let Some(v) = root.attribute("version") {
            match v
                .split('.')
                .next()
                .and_then(|m| m.trim().parse::<u32>().ok())
            {
                Some(0 | 1) => upgrade = true,
                Some(_) => {}
                None => {
                    return Err(src.error(
                        root.range().start,
                        format!("scene version \"{v}\" is not a version number (e.g. \"3.0.0\")"),
                    ))
                }
            }
        }
        // Defaults first, wherever they are among the scene's children.
        for d in root.children().filter(|c| c.has_tag_name("default")) {
            let at = d.range().start;
            let (Some(name), Some(value)) = (d.attribute("name"), d.attribute("value")) else {
                return Err(src.error(at, "<default> needs \"name\" and \"value\""));
            };
            // A default only fills a parameter nobody has set (-D, or an earlier file).
            self.params
                .entry(name.to_string())
                .or_insert_with(|| value.to_string());
        }
        let mut scene = self.convert(&src, root, 0, upgrade)?;
        let mut children = Vec::new();
        for c in std::mem::take(&mut scene.children) {
            match c.tag.as_str() {
                "default" => {}
                "include" => children.extend(self.include(path, &c, depth)?.children),
                _ => children.push(c),
            }
        }
        scene.children = children;
        Ok(scene)
    }

    fn include(&mut self, path: &Path, node: &Node, depth: usize) -> Result<Node, LoadError> {
        if depth >= MAX_INCLUDE_DEPTH {
            return Err(node.error("includes nest too deep (is a file including itself?)"));
        }
        let name = node.req("filename")?;
        let file = path.parent().unwrap_or(Path::new("")).join(name);
        let text = std::fs::read_to_string(&file).map_err(|e| {
            node.error(format!("cannot read included file {}: {e}", file.display()))
        })?;
        self.parse_text(&file, &text, depth + 1)
    }

    fn convert(
        &self,
        src: &Source,
        e: roxmltree::Node,
        depth: usize,
        upgrade: bool,
    ) -> Result<Node, LoadError> {
        let at = e.range().start;
        if depth >= MAX_NESTING {
            return Err(src.error(
                at,
                format!("elements nest deeper than {MAX_NESTING} levels"),
            ));
        }
        let mut attrs = Vec::new();
        for a in e.attributes() {
            let value = self
                .substitute(a.value())
                .map_err(|m| src.error(a.range().start, m))?;
            let value = if upgrade && a.name() == "name" && !e.has_tag_name("default") {
                snake_case(&value)
            } else {
                value
            };
            attrs.push((a.name().to_string(), value));
        }
        let mut children: Vec<Node> = e
            .children()
            .filter(|c| c.is_element())
            .map(|c| self.convert(src, c, depth + 1, upgrade))
            .collect::<Result<_, _>>()?;
        // Mitsuba 0.6's `diffuse` also took `diffuseReflectance`, which Mitsuba 3 renames.
        if upgrade && e.has_tag_name("bsdf") && e.attribute("type") == Some("diffuse") {
            for c in &mut children {
                for (k, v) in &mut c.attrs {
                    if k == "name" && v == "diffuse_reflectance" {
                        *v = "reflectance".to_string();
                    }
                }
            }
        }
        Ok(Node {
            tag: e.tag_name().name().to_string(),
            attrs,
            children,
            span: src.span(at),
            used: Cell::new(false),
        })
    }

    /// Replaces every `$name` by its parameter's value.
    fn substitute(&self, value: &str) -> Result<String, String> {
        let mut out = String::with_capacity(value.len());
        let mut rest = value;
        while let Some(i) = rest.find('$') {
            out.push_str(&rest[..i]);
            let after = &rest[i + 1..];
            let len = after
                .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
                .unwrap_or(after.len());
            let name = &after[..len];
            match self.params.get(name) {
                Some(v) => out.push_str(v),
                None => {
                    return Err(format!(
                    "undefined parameter \"${name}\" (give it with -D {name}=VALUE or a <default>)"
                ))
                }
            }
            rest = &after[len..];
        }
        out.push_str(rest);
        Ok(out)
    }
}
