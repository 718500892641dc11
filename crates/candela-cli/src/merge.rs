//! `candela merge`: adds film parts of one render (disjoint sample ranges, see
//! [`crate::part`]) into the film of their union. The sums are exact integers, so any
//! split of `0..N`, merged in any order, is the single `0..N` render bit for bit.

use std::ops::Range;
use std::path::{Path, PathBuf};

use candela_core::film::Film;

use crate::output::{write_image, ImageFormat, LinearImage};
use crate::part::{read_part, write_part, PartInfo};
use crate::tonemap::DisplayTransform;
use crate::UserError;

/// A film part and the name it is reported under (its file).
pub struct NamedPart {
    pub name: String,
    pub film: Film,
    pub info: PartInfo,
}

/// Merges parts after checking that they belong to one render (same fingerprint,
/// resolution, seed and spp) and hold disjoint sample ranges.
pub fn merge_parts(parts: &[NamedPart]) -> Result<(Film, PartInfo), UserError> {
    let first = parts
        .first()
        .ok_or_else(|| UserError("merge needs at least one part".into()))?;
    let (w, h) = (first.film.width, first.film.height);
    for p in &parts[1..] {
        let differ = |what: String| {
            UserError(format!(
                "{}: cannot merge with {}: {what}",
                p.name, first.name
            ))
        };
        if (p.film.width, p.film.height) != (w, h) {
            return Err(differ(format!(
                "resolution {}x{} differs from {w}x{h}",
                p.film.width, p.film.height
            )));
        }
        if p.info.seed != first.info.seed {
            return Err(differ(format!(
                "seed {} differs from {}",
                p.info.seed, first.info.seed
            )));
        }
        if p.info.spp != first.info.spp {
            return Err(differ(format!(
                "it is a part of a {} spp render, not {} spp",
                p.info.spp, first.info.spp
            )));
        }
        if p.info.fingerprint != first.info.fingerprint {
            return Err(differ(format!(
                "rendered from a different scene or settings (fingerprint {:016x}, not {:016x})",
                p.info.fingerprint, first.info.fingerprint
            )));
        }
    }
    let mut ranges: Vec<(Range<u32>, &str)> = parts
        .iter()
        .flat_map(|p| p.info.samples.iter().map(|r| (r.clone(), p.name.as_str())))
        .collect();
    ranges.sort_by_key(|(r, _)| (r.start, r.end));
    for pair in ranges.windows(2) {
        let ((a, an), (b, bn)) = (&pair[0], &pair[1]);
        if b.start < a.end {
            return Err(UserError(format!(
                "{bn}: samples {}..{} overlap samples {}..{} of {an}; parts must hold disjoint sample ranges",
                b.start, b.end, a.start, a.end
            )));
        }
    }
    let mut film = Film::new(w, h);
    for p in parts {
        film.merge(&p.film);
    }
    let info = PartInfo {
        samples: coalesce(ranges.into_iter().map(|(r, _)| r)),
        ..first.info.clone()
    };
    Ok((film, info))
}

/// Sorted disjoint ranges with touching neighbours joined.
pub fn coalesce(sorted: impl IntoIterator<Item = Range<u32>>) -> Vec<Range<u32>> {
    let mut out: Vec<Range<u32>> = Vec::new();
    for r in sorted {
        match out.last_mut() {
            Some(last) if last.end == r.start => last.end = r.end,
            _ => out.push(r),
        }
    }
    out
}

/// `candela merge PARTS… -o OUT`: an `.exr` output is itself a part (mergeable again,
/// and viewable); `.pfm` and `.png` get the resolved image only.
pub fn run(inputs: &[PathBuf], output: &Path, display: &DisplayTransform) -> Result<(), UserError> {
    let format = ImageFormat::from_path(output)?;
    let parts = inputs
        .iter()
        .map(|path| {
            let (film, info) = read_part(path)?;
            Ok(NamedPart {
                name: path.display().to_string(),
                film,
                info,
            })
        })
        .collect::<Result<Vec<_>, UserError>>()?;
    let (film, info) = merge_parts(&parts)?;
    if format == ImageFormat::Exr {
        write_part(output, &film, &info)?;
    } else {
        let pixels = film.resolve();
        let image = LinearImage {
            width: film.width,
            height: film.height,
            pixels: &pixels,
        };
        write_image(output, &image, display)?;
    }
    let held: Vec<String> = info
        .samples
        .iter()
        .map(|r| format!("{}..{}", r.start, r.end))
        .collect();
    let note = if info.is_complete() {
        "complete".to_string()
    } else {
        format!("partial: {} of {} spp", held.join(","), info.spp)
    };
    println!(
        "merged {} parts, {}x{}, {note} -> {}",
        parts.len(),
        film.width,
        film.height,
        output.display()
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn part(name: &str, samples: Range<u32>) -> NamedPart {
        NamedPart {
            name: name.into(),
            film: Film::new(2, 2),
            info: PartInfo {
                fingerprint: 7,
                seed: 1,
                spp: 16,
                samples: vec![samples],
            },
        }
    }

    #[test]
    fn parts_of_other_renders_or_overlapping_ranges_are_refused() {
        let err = |parts: &[NamedPart]| merge_parts(parts).err().unwrap().0;
        let mut other_seed = part("b", 8..16);
        other_seed.info.seed = 2;
        assert!(err(&[part("a", 0..8), other_seed]).contains("seed 2 differs"));
        let mut other_scene = part("b", 8..16);
        other_scene.info.fingerprint = 8;
        assert!(err(&[part("a", 0..8), other_scene]).contains("different scene"));
        let mut other_size = part("b", 8..16);
        other_size.film = Film::new(3, 2);
        assert!(err(&[part("a", 0..8), other_size]).contains("resolution 3x2"));
        let mut other_spp = part("b", 8..16);
        other_spp.info.spp = 32;
        assert!(err(&[part("a", 0..8), other_spp]).contains("32 spp"));
        let e = err(&[part("a", 0..8), part("b", 4..16)]);
        assert!(
            e.starts_with("b: samples 4..16 overlap samples 0..8 of a"),
            "{e}"
        );
    }

    #[test]
    fn disjoint_ranges_merge_into_their_union() {
        let parts = [part("b", 8..12), part("a", 0..8), part("c", 12..16)];
        let (_, info) = merge_parts(&parts).unwrap();
        assert_eq!((info.samples.len(), &info.samples[0]), (1, &(0..16)));
        assert!(info.is_complete());
        let (_, info) = merge_parts(&parts[..2]).unwrap();
        assert_eq!((info.samples.len(), &info.samples[0]), (1, &(0..12)));
        assert!(!info.is_complete());
    }
}
