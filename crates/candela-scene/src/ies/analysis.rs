//! What `candela ies FILE` shows: a summary of a profile (header, lumens integrated from
//! the table against the stated lumens, peak candela, beam angle) and its polar
//! intensity curves.

use candela_core::photometry::{plane_dir, GoniometricTable};
use image::{Rgb, RgbImage};

use super::{IesFile, IesUnits, IesVersion, Tilt};
use crate::LoadError;

/// The figures of merit of a photometric profile.
#[derive(Clone, Debug, PartialEq)]
pub struct IesSummary {
    /// Human-readable header: version, keywords, lamps, units, factors, angles.
    pub header_lines: Vec<String>,
    /// ∫ I dω of the goniometric table (lm), with every factor applied.
    pub integrated_lumens: f64,
    /// Lamps × rated lumens per lamp; `None` for absolute photometry.
    pub stated_lumens: Option<f64>,
    pub peak_candela: f64,
    /// See [`GoniometricTable::beam_angle`].
    pub beam_angle_deg: f64,
}

/// Summarizes a parsed file (fails only for an `IesFile` edited into an invalid state).
pub fn summary(ies: &IesFile) -> Result<IesSummary, LoadError> {
    let table = ies.table()?;
    let mut header_lines = vec![format!(
        "version: {}",
        match ies.version {
            IesVersion::Lm63_1986 => "LM-63-1986",
            IesVersion::Lm63_1991 => "LM-63-1991",
            IesVersion::Lm63_1995 => "LM-63-1995",
            IesVersion::Lm63_2002 => "LM-63-2002",
            IesVersion::Lm63_2019 => "LM-63-2019",
        }
    )];
    header_lines.extend(ies.text.iter().filter(|l| !l.trim().is_empty()).cloned());
    for (key, value) in &ies.keywords {
        header_lines.push(format!("[{key}] {}", value.replace('\n', " ")));
    }
    let lumens = match ies.stated_lumens() {
        Some(l) => format!("{} × {} lm = {l} lm", ies.lamp_count, ies.lumens_per_lamp),
        None => format!("{} (absolute photometry)", ies.lamp_count),
    };
    header_lines.push(format!("lamps: {lumens}"));
    let units = match ies.units {
        IesUnits::Feet => "ft",
        IesUnits::Meters => "m",
    };
    let [w, l, h] = ies.dimensions;
    header_lines.push(format!("luminous opening: {w} × {l} × {h} {units}"));
    header_lines.push(format!(
        "candela multiplier {}, ballast factor {}, ballast-lamp factor {}, input {} W",
        ies.multiplier, ies.ballast_factor, ies.ballast_lamp_factor, ies.input_watts
    ));
    header_lines.push(match &ies.tilt {
        Tilt::None => "tilt: none".into(),
        Tilt::Include(t) => format!("tilt: included, {} angles", t.angles.len()),
        Tilt::File(name, t) => format!("tilt: from {name}, {} angles", t.angles.len()),
    });
    let (v, hz) = (&ies.vertical_angles, &ies.horizontal_angles);
    header_lines.push(format!(
        "angles: {} vertical ({}–{}°) × {} horizontal ({}–{}°), symmetry {:?}",
        v.len(),
        v[0],
        v[v.len() - 1],
        hz.len(),
        hz[0],
        hz[hz.len() - 1],
        ies.symmetry()
    ));
    Ok(IesSummary {
        header_lines,
        integrated_lumens: table.total_flux(),
        stated_lumens: ies.stated_lumens(),
        peak_candela: table.max_intensity() as f64,
        beam_angle_deg: table.beam_angle(),
    })
}

/// A `size` × `size` polar intensity diagram: nadir down, the C0–C180 curve in red (C0 to
/// the right) and the C90–C270 curve in blue (C90 to the right), rings at 25, 50, 75 and
/// 100% of the peak candela.
pub fn polar_plot(ies: &IesFile, size: u32) -> Result<RgbImage, LoadError> {
    let table = ies.table()?;
    let size = size.max(16);
    let mut img = RgbImage::from_pixel(size, size, Rgb([255, 255, 255]));
    let c = size as f64 / 2.0;
    let radius = 0.45 * size as f64;
    let grey = Rgb([200, 200, 200]);
    let to_px = |r: f64, s_deg: f64| {
        let s = s_deg.to_radians();
        (c + r * s.sin(), c + r * s.cos())
    };
    for ring in [0.25, 0.5, 0.75, 1.0] {
        draw_curve(
            &mut img,
            grey,
            (0..=720).map(|k| to_px(ring * radius, k as f64 * 0.5)),
        );
    }
    for s in [0.0, 90.0, 45.0, 135.0] {
        let (a, b) = (to_px(radius, s), to_px(radius, s + 180.0));
        draw_curve(&mut img, grey, [a, b].into_iter());
    }
    let peak = table.max_intensity() as f64;
    if peak > 0.0 {
        for (plane, colour) in [(0.0, Rgb([210, 30, 30])), (90.0, Rgb([30, 60, 210]))] {
            let curve = plane_curve(&table, plane, peak)
                .into_iter()
                .map(|(r, s)| to_px(r * radius, s));
            draw_curve(&mut img, colour, curve);
        }
    }
    Ok(img)
}

/// (I / peak, signed angle in degrees) around plane C`c`–C`c + 180`, every 0.25°.
fn plane_curve(table: &GoniometricTable, c: f64, peak: f64) -> Vec<(f64, f64)> {
    (-720..=720)
        .map(|k| {
            let s = k as f64 * 0.25;
            (table.intensity(plane_dir(c, s)) as f64 / peak, s)
        })
        .collect()
}

/// Joins consecutive points with 2-pixel-wide straight segments.
fn draw_curve(img: &mut RgbImage, colour: Rgb<u8>, points: impl Iterator<Item = (f64, f64)>) {
    let (w, h) = (img.width() as f64, img.height() as f64);
    let mut prev: Option<(f64, f64)> = None;
    for p in points {
        let a = prev.unwrap_or(p);
        let steps = ((p.0 - a.0).abs().max((p.1 - a.1).abs()).ceil() as usize).max(1);
        for k in 0..=steps {
            let t = k as f64 / steps as f64;
            let (x, y) = (a.0 + t * (p.0 - a.0), a.1 + t * (p.1 - a.1));
            for (dx, dy) in [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)] {
                let (px, py) = (x + dx - 0.5, y + dy - 0.5);
                if px >= 0.0 && py >= 0.0 && px < w && py < h {
                    img.put_pixel(px as u32, py as u32, colour);
                }
            }
        }
        prev = Some(p);
    }
}
