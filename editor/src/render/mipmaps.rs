//! Mipmaps of a base colour texture ([`mip_chain`]): each level half the size of the one above
//! (rounded down, at least one texel), made when the texture is uploaded, so that a texture seen
//! small is read from a copy of about its size on screen instead of flickering between texels.
//! Each texel is the mean of the 2×2 texels above it (an odd last row or column is left out),
//! averaged in linear light, as the texels are sRGB-encoded (averaging the encoded values would
//! darken every edge between light and dark); alpha is averaged as it is.

/// One level of a texture: sRGB-encoded RGBA8 rows, top row first.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct MipLevel {
    pub width: u32,
    pub height: u32,
    pub rgba: Vec<u8>,
}

/// The levels below a `width` × `height` texture, down to 1 × 1 (none for a 1 × 1 texture).
pub fn mip_chain(width: u32, height: u32, rgba: &[u8]) -> Vec<MipLevel> {
    let linear: Vec<f32> = (0..=255u8).map(srgb_to_linear).collect();
    let mut levels: Vec<MipLevel> = Vec::new();
    let (mut w, mut h) = (width, height);
    while w > 1 || h > 1 {
        let above = levels.last().map_or(rgba, |l| &l.rgba);
        let level = halve(w, h, above, &linear);
        (w, h) = (level.width, level.height);
        levels.push(level);
    }
    levels
}

/// The level below a `w` × `h` one.
fn halve(w: u32, h: u32, rgba: &[u8], linear: &[f32]) -> MipLevel {
    let (width, height) = ((w / 2).max(1), (h / 2).max(1));
    let (w, h) = (w as usize, h as usize);
    let mut out = Vec::with_capacity(width as usize * height as usize * 4);
    for y in 0..height as usize {
        // A side of one texel stays one: its texel is read twice.
        let rows = [(2 * y).min(h - 1), (2 * y + 1).min(h - 1)];
        for x in 0..width as usize {
            let columns = [(2 * x).min(w - 1), (2 * x + 1).min(w - 1)];
            let mut sum = [0.0f32; 4];
            for row in rows {
                for column in columns {
                    let texel = &rgba[(row * w + column) * 4..][..4];
                    for c in 0..3 {
                        sum[c] += linear[texel[c] as usize];
                    }
                    sum[3] += f32::from(texel[3]);
                }
            }
            for value in &sum[..3] {
                out.push(linear_to_srgb(value / 4.0));
            }
            out.push((sum[3] / 4.0).round() as u8);
        }
    }
    MipLevel {
        width,
        height,
        rgba: out,
    }
}

fn srgb_to_linear(encoded: u8) -> f32 {
    let c = f32::from(encoded) / 255.0;
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

fn linear_to_srgb(c: f32) -> u8 {
    let c = c.clamp(0.0, 1.0);
    let encoded = if c <= 0.003_130_8 {
        c * 12.92
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    };
    (encoded * 255.0).round() as u8
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn levels_halve_down_to_one_texel() {
        let rgba = vec![200u8; 10 * 3 * 4];
        let sizes: Vec<(u32, u32)> = mip_chain(10, 3, &rgba)
            .iter()
            .map(|l| (l.width, l.height))
            .collect();
        assert_eq!(sizes, [(5, 1), (2, 1), (1, 1)]);
        assert!(mip_chain(1, 1, &[1, 2, 3, 4]).is_empty());
        // A flat colour stays that colour at every level.
        for level in mip_chain(10, 3, &rgba) {
            assert!(level.rgba.iter().all(|&c| c == 200), "{level:?}");
        }
    }

    #[test]
    fn black_and_white_average_in_linear_light() {
        // A 2×2 checker of black and white: the mean is half the light, sRGB 188, not 128.
        let (black, white) = ([0, 0, 0, 255], [255, 255, 255, 255]);
        let rgba: Vec<u8> = [black, white, white, black].concat();
        let levels = mip_chain(2, 2, &rgba);
        assert_eq!(levels.len(), 1);
        assert_eq!(levels[0].rgba, [188, 188, 188, 255]);
    }

    #[test]
    fn alpha_is_averaged_as_it_is() {
        let rgba: Vec<u8> = [[255, 0, 0, 0], [255, 0, 0, 255]].concat();
        assert_eq!(mip_chain(2, 1, &rgba)[0].rgba, [255, 0, 0, 128]);
    }
}
