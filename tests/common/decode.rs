//! Decoders for the recordings the fitting tests and benchmark read from Debian packages: FLAC
//! files (Sonic Pi's samples) and Gravis UltraSound patches (freepats). SoundFont samples are read
//! by [`super::sf2`].

use std::path::Path;

use modal_resonator::authoring::fit::Recording;

/// A FLAC file as mono (channels averaged), full scale 1.
pub fn read_flac(path: &Path, position: &str) -> Recording {
    let mut reader = claxon::FlacReader::open(path).unwrap();
    let info = reader.streaminfo();
    let channels = info.channels as usize;
    let full_scale = (1i64 << (info.bits_per_sample - 1)) as f32;
    let interleaved: Vec<i32> = reader.samples().map(|s| s.unwrap()).collect();
    let samples = interleaved
        .chunks_exact(channels)
        .map(|f| f.iter().map(|&v| v as f32).sum::<f32>() / (channels as f32 * full_scale))
        .collect();
    Recording::new(position, samples, info.sample_rate)
}

/// Sample `index` of a Gravis UltraSound patch (the GF1PATCH110 format of freepats): the raw
/// 8- or 16-bit PCM recording, before any looping.
pub fn read_gus_patch(path: &Path, index: usize, position: &str) -> Recording {
    // Bytes of the patch header, the instrument header, the layer header and each sample's
    // header, which precedes its PCM data (GF1PATCH110 layout).
    const HEADER: usize = 129;
    const INSTRUMENT: usize = 63;
    const LAYER: usize = 47;
    const SAMPLE: usize = 96;
    let data = std::fs::read(path).unwrap();
    assert!(
        data.starts_with(b"GF1PATCH110"),
        "{}: not a GUS patch",
        path.display()
    );
    let u16_at = |o: usize| u16::from_le_bytes([data[o], data[o + 1]]);
    let u32_at = |o: usize| u32::from_le_bytes(data[o..o + 4].try_into().unwrap());
    let num_samples = data[HEADER + INSTRUMENT + 6] as usize;
    assert!(
        index < num_samples,
        "{}: {num_samples} samples",
        path.display()
    );
    let mut offset = HEADER + INSTRUMENT + LAYER;
    for _ in 0..index {
        offset += SAMPLE + u32_at(offset + 8) as usize;
    }
    let len_bytes = u32_at(offset + 8) as usize;
    let rate = u16_at(offset + 20) as u32;
    let modes = data[offset + 55];
    let (sixteen_bit, unsigned) = (modes & 1 != 0, modes & 2 != 0);
    let pcm = &data[offset + SAMPLE..offset + SAMPLE + len_bytes];
    let samples = if sixteen_bit {
        pcm.chunks_exact(2)
            .map(|b| {
                let v = u16::from_le_bytes([b[0], b[1]]);
                let v = if unsigned {
                    v as i32 - 32768
                } else {
                    v as i16 as i32
                };
                v as f32 / 32768.0
            })
            .collect()
    } else {
        pcm.iter()
            .map(|&b| {
                let v = if unsigned {
                    b as i32 - 128
                } else {
                    b as i8 as i32
                };
                v as f32 / 128.0
            })
            .collect()
    };
    Recording::new(position, samples, rate)
}
