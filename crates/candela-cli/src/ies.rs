//! `candela ies`: what a photometric profile says and what its table integrates to.

use std::io::Cursor;
use std::path::Path;

use candela_scene::ies::{load_ies, polar_plot, summary};

use crate::output::write_atomically;
use crate::UserError;

pub fn run(path: &Path, plot: Option<&Path>) -> Result<(), UserError> {
    let ies = load_ies(path)?;
    let s = summary(&ies)?;
    println!("file             {}", path.display());
    for line in &s.header_lines {
        println!("  {line}");
    }
    match s.stated_lumens {
        Some(stated) => println!(
            "lumens           {:.1} integrated from the table, {:.1} stated (ratio {:.3})",
            s.integrated_lumens,
            stated,
            s.integrated_lumens / stated
        ),
        None => println!(
            "lumens           {:.1} integrated from the table (absolute photometry)",
            s.integrated_lumens
        ),
    }
    println!("peak intensity   {:.1} cd", s.peak_candela);
    println!(
        "beam angle       {:.1}° (full width at half maximum)",
        s.beam_angle_deg
    );
    if let Some(out) = plot {
        let image = polar_plot(&ies, 512)?;
        let mut bytes = Cursor::new(Vec::new());
        image
            .write_to(&mut bytes, image::ImageFormat::Png)
            .map_err(|e| UserError(format!("{}: cannot encode plot: {e}", out.display())))?;
        write_atomically(out, bytes.get_ref())?;
        println!("polar plot       {}", out.display());
    }
    Ok(())
}
