//! Film parts: the film of a range of sample indices, in an OpenEXR file that carries
//! its exact per-pixel sums, so that parts rendered apart merge into the film of their
//! union bit for bit ([`merge`]).
//!
//! A part file has the resolved image as usual (`R`, `G`, `B`, f32, viewable anywhere)
//! and, per pixel, the film's fixed-point sums ([`candela_core::exact_sum`]) as four
//! little-endian u32 words each (`candela.R0`…`candela.R3`, the same for `G`, `B` and
//! the weight `W`), the sample count `candela.samples` and the count of dropped samples
//! `candela.rejected`. One text attribute `candela.part` says what the part holds:
//! `format=1;fingerprint=<16 hex digits>;seed=<n>;spp=<N>;samples=<a..b,c..d>`, where
//! the fingerprint is [`candela_core::fingerprint::fingerprint`] of the scene as
//! rendered (its settings included) and `spp` the total sample count of the whole render.

use std::io::Cursor;
use std::ops::Range;
use std::path::Path;

use candela_core::exact_sum::ExactSum;
use candela_core::film::{Film, Pixel};

use crate::output::write_atomically;
use crate::UserError;

/// The attribute holding a part's description.
const ATTRIBUTE: &str = "candela.part";
/// Words of one fixed-point sum.
const WORDS: usize = 4;
/// Channel-name prefixes of the sums, in the order of [`sums`].
const SUMS: [&str; 4] = ["R", "G", "B", "W"];

/// What a part holds, besides its film.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PartInfo {
    /// The scene's fingerprint, settings included.
    pub fingerprint: u64,
    pub seed: u64,
    /// Samples per pixel of the whole render the part belongs to.
    pub spp: u32,
    /// Disjoint sample-index ranges the part holds, sorted and coalesced.
    pub samples: Vec<Range<u32>>,
}

impl PartInfo {
    /// Whether the part holds every sample of its render.
    pub fn is_complete(&self) -> bool {
        self.samples.len() == 1 && self.samples[0] == (0..self.spp)
    }

    fn encode(&self) -> String {
        format!(
            "format=1;fingerprint={:016x};seed={};spp={};samples={}",
            self.fingerprint,
            self.seed,
            self.spp,
            ranges_text(&self.samples)
        )
    }

    fn decode(text: &str) -> Option<PartInfo> {
        let mut fields = std::collections::BTreeMap::new();
        for kv in text.split(';') {
            let (k, v) = kv.split_once('=')?;
            fields.insert(k, v);
        }
        if fields.get("format") != Some(&"1") {
            return None;
        }
        let samples = fields
            .get("samples")?
            .split(',')
            .map(|r| parse_range(r).ok())
            .collect::<Option<Vec<_>>>()?;
        Some(PartInfo {
            fingerprint: u64::from_str_radix(fields.get("fingerprint")?, 16).ok()?,
            seed: fields.get("seed")?.parse().ok()?,
            spp: fields.get("spp")?.parse().ok()?,
            samples,
        })
    }
}

/// `a..b` as the CLI and part files spell a range of sample indices (`b > a`).
pub fn parse_range(s: &str) -> Result<Range<u32>, String> {
    let bad = || format!("expected a sample range START..END (e.g. 64..128), got \"{s}\"");
    let (a, b) = s.split_once("..").ok_or_else(bad)?;
    let a: u32 = a.trim().parse().map_err(|_| bad())?;
    let b: u32 = b.trim().parse().map_err(|_| bad())?;
    if b <= a {
        return Err(format!("sample range {s} is empty (END must exceed START)"));
    }
    Ok(a..b)
}

fn ranges_text(ranges: &[Range<u32>]) -> String {
    let parts: Vec<String> = ranges
        .iter()
        .map(|r| format!("{}..{}", r.start, r.end))
        .collect();
    parts.join(",")
}

/// The four sums of a pixel, in the order of [`SUMS`].
fn sums(p: &Pixel) -> [ExactSum; 4] {
    [
        p.radiance_sum[0],
        p.radiance_sum[1],
        p.radiance_sum[2],
        p.weight_sum,
    ]
}

/// Encodes a part file (see the module docs).
pub fn encode_part(film: &Film, info: &PartInfo) -> std::result::Result<Vec<u8>, String> {
    use exr::prelude::*;
    let n = film.pixels.len();
    let resolved = film.resolve();
    let mut list: Vec<AnyChannel<FlatSamples>> = ["R", "G", "B"]
        .iter()
        .enumerate()
        .map(|(c, name)| {
            let v = resolved.iter().map(|p| p[c]).collect();
            AnyChannel::new(*name, FlatSamples::F32(v))
        })
        .collect();
    for (s, name) in SUMS.iter().enumerate() {
        for word in 0..WORDS {
            let v = film
                .pixels
                .iter()
                .map(|p| (sums(p)[s].to_bits() as u128 >> (32 * word)) as u32)
                .collect();
            list.push(AnyChannel::new(
                format!("candela.{name}{word}").as_str(),
                FlatSamples::U32(v),
            ));
        }
    }
    let counts = |f: fn(&Pixel) -> u32| FlatSamples::U32(film.pixels.iter().map(f).collect());
    list.push(AnyChannel::new("candela.samples", counts(|p| p.samples)));
    list.push(AnyChannel::new("candela.rejected", counts(|p| p.rejected)));
    debug_assert!(list.iter().all(|c| c.sample_data.len() == n));
    let mut attributes = LayerAttributes::default();
    attributes.other.insert(
        Text::from(ATTRIBUTE),
        AttributeValue::Text(Text::from(info.encode().as_str())),
    );
    let encoding = Encoding {
        compression: Compression::ZIP16,
        blocks: Blocks::ScanLines,
        line_order: LineOrder::Increasing,
    };
    let layer = Layer::new(
        (film.width as usize, film.height as usize),
        attributes,
        encoding,
        AnyChannels::sort(list.into()),
    );
    let mut out = Cursor::new(Vec::new());
    Image::from_layer(layer)
        .write()
        .to_buffered(&mut out)
        .map_err(|e| e.to_string())?;
    Ok(out.into_inner())
}

/// Writes a part file atomically.
pub fn write_part(path: &Path, film: &Film, info: &PartInfo) -> Result<(), UserError> {
    let bytes = encode_part(film, info)
        .map_err(|e| UserError(format!("{}: cannot encode film: {e}", path.display())))?;
    write_atomically(path, &bytes)
}

/// Reads a part file written by [`write_part`].
pub fn read_part(path: &Path) -> Result<(Film, PartInfo), UserError> {
    let fail = |what: &str| UserError(format!("{}: {what}", path.display()));
    let bytes = std::fs::read(path).map_err(|e| fail(&format!("cannot read: {e}")))?;
    decode_part(&bytes).map_err(|e| fail(&e))
}

/// Decodes a part file's bytes.
pub fn decode_part(bytes: &[u8]) -> std::result::Result<(Film, PartInfo), String> {
    use exr::prelude::*;
    let image = read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .from_buffered(Cursor::new(bytes))
        .map_err(|e| format!("not a readable OpenEXR file: {e}"))?;
    let layer = image.layer_data;
    let not_part = "not a Candela film part (render it with --samples or `candela merge` \
                    it to .exr; plain images carry no sums to merge)";
    let info = match layer.attributes.other.get(&Text::from(ATTRIBUTE)) {
        Some(AttributeValue::Text(t)) => {
            PartInfo::decode(&t.to_string()).ok_or("its candela.part attribute is malformed")?
        }
        _ => return Err(not_part.into()),
    };
    let (w, h) = (layer.size.x(), layer.size.y());
    let n = w * h;
    let channel = |name: &str| -> std::result::Result<&[u32], String> {
        let c = layer.channel_data.list.iter().find(|c| c.name == *name);
        match c.map(|c| &c.sample_data) {
            Some(FlatSamples::U32(v)) if v.len() == n => Ok(v),
            _ => Err(format!("its channel {name} is missing or not u32")),
        }
    };
    let mut words = Vec::new();
    for name in SUMS {
        for word in 0..WORDS {
            words.push(channel(&format!("candela.{name}{word}"))?);
        }
    }
    let (samples, rejected) = (channel("candela.samples")?, channel("candela.rejected")?);
    let sum = |s: usize, i: usize| {
        let bits = (0..WORDS).fold(0u128, |acc, w| {
            acc | (words[s * WORDS + w][i] as u128) << (32 * w)
        });
        ExactSum::from_bits(bits as i128)
    };
    let mut film = Film::new(w as u32, h as u32);
    for (i, p) in film.pixels.iter_mut().enumerate() {
        *p = Pixel {
            radiance_sum: [sum(0, i), sum(1, i), sum(2, i)],
            weight_sum: sum(3, i),
            samples: samples[i],
            rejected: rejected[i],
        };
    }
    Ok((film, info))
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn a_part_round_trips_through_its_file() {
        let mut film = Film::new(3, 2);
        for (i, v) in [0.1f32, 1e9, 3.5e-12, 7.0, 0.0, 2.25]
            .into_iter()
            .enumerate()
        {
            film.pixels[i].add(Vec3::new(v, -v, 0.5 * v), 1.0);
            film.pixels[i].add(Vec3::splat(f32::NAN), 1.0);
        }
        let info = PartInfo {
            fingerprint: 0xdead_beef_0123_4567,
            seed: 42,
            spp: 128,
            samples: vec![0..16, 64..128],
        };
        let bytes = encode_part(&film, &info).unwrap();
        let (back, back_info) = decode_part(&bytes).unwrap();
        assert_eq!(back, film);
        assert_eq!(back_info, info);
        assert_eq!(
            encode_part(&film, &info).unwrap(),
            bytes,
            "same bytes every time"
        );
    }

    #[test]
    fn ranges_parse_and_refuse_nonsense() {
        assert_eq!(parse_range("64..128"), Ok(64..128));
        for bad in ["64", "8..8", "9..3", "a..b", "-1..4"] {
            assert!(parse_range(bad).is_err(), "{bad}");
        }
    }
}
