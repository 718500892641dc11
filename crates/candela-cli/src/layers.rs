//! Multi-layer EXR: the beauty as the unnamed layer (`R`, `G`, `B`, what viewers show)
//! and the other passes as named layers, `layer.channel` (`albedo.R`, `normal.X`,
//! `depth.Z`, `noisy.R`), the naming of OpenEXR's layer convention that Nuke, Blender,
//! Houdini and OIDN's own tools read.

use std::io::Cursor;

use exr::prelude::*;

/// One channel: its full name (`R`, `albedo.G`) and its values, row-major.
pub struct Channel {
    pub name: String,
    pub values: Vec<f32>,
}

/// Encodes `channels` (each `width · height` values) as one EXR part, channels sorted
/// by name as the format requires, tiles written in increasing order (bytes that depend
/// only on the pixels, as `output::encode_exr` writes them).
pub fn encode_layered_exr(
    width: u32,
    height: u32,
    channels: Vec<Channel>,
) -> std::result::Result<Vec<u8>, String> {
    let n = width as usize * height as usize;
    let list: SmallVec<[AnyChannel<FlatSamples>; 4]> = channels
        .into_iter()
        .map(|c| {
            assert_eq!(
                c.values.len(),
                n,
                "channel {} has one value a pixel",
                c.name
            );
            AnyChannel::new(c.name.as_str(), FlatSamples::F32(c.values))
        })
        .collect();
    let encoding = Encoding {
        line_order: LineOrder::Increasing,
        ..Encoding::FAST_LOSSLESS
    };
    let image = Image::from_encoded_channels(
        (width as usize, height as usize),
        encoding,
        AnyChannels::sort(list),
    );
    let mut out = Cursor::new(Vec::new());
    image
        .write()
        .to_buffered(&mut out)
        .map_err(|e| e.to_string())?;
    Ok(out.into_inner())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn layers_read_back_by_name() {
        let channels = ["R", "G", "B", "albedo.R", "depth.Z"]
            .iter()
            .enumerate()
            .map(|(i, name)| Channel {
                name: name.to_string(),
                values: vec![i as f32; 6],
            })
            .collect();
        let bytes = encode_layered_exr(3, 2, channels).unwrap();
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("layers.exr");
        std::fs::write(&path, bytes).unwrap();
        let image = read_all_flat_layers_from_file(&path).unwrap();
        let layer = &image.layer_data[0];
        let value = |name: &str| {
            let c = layer
                .channel_data
                .list
                .iter()
                .find(|c| c.name == *name)
                .unwrap_or_else(|| panic!("no channel {name}"));
            c.sample_data.value_by_flat_index(5).to_f32()
        };
        assert_eq!(value("R"), 0.0);
        assert_eq!(value("albedo.R"), 3.0);
        assert_eq!(value("depth.Z"), 4.0);
    }
}
