//! The heat map's colour map: viridis (van der Walt and Smith, designed to be perceptually uniform
//! and readable with colour-vision deficiencies), as ten key colours interpolated linearly in sRGB.
//! Linear interpolation between keys this close keeps the map's lightness monotonic.

/// Viridis at t = 0, 1/9, ..., 1 (sRGB, 8 bits per channel).
const VIRIDIS_KEYS: [[u8; 3]; 10] = [
    [0x44, 0x01, 0x54],
    [0x48, 0x28, 0x78],
    [0x3e, 0x4a, 0x89],
    [0x31, 0x68, 0x8e],
    [0x26, 0x82, 0x8e],
    [0x1f, 0x9e, 0x89],
    [0x35, 0xb7, 0x79],
    [0x6d, 0xcd, 0x59],
    [0xb4, 0xde, 0x2c],
    [0xfd, 0xe7, 0x25],
];

/// Colour for `t` in 0..=1 (clamped; NaN maps to 0), as sRGB in 0..=1.
pub fn viridis(t: f32) -> [f32; 3] {
    let t = if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) };
    let x = t * (VIRIDIS_KEYS.len() - 1) as f32;
    let i = (x.floor() as usize).min(VIRIDIS_KEYS.len() - 2);
    let f = x - i as f32;
    let (a, b) = (VIRIDIS_KEYS[i], VIRIDIS_KEYS[i + 1]);
    std::array::from_fn(|c| (a[c] as f32 * (1.0 - f) + b[c] as f32 * f) / 255.0)
}

/// The colour map as an RGBA8 strip of `width` texels (for the legend and the shader's lookup).
pub fn viridis_strip(width: usize) -> Vec<[u8; 4]> {
    (0..width)
        .map(|i| {
            let [r, g, b] = viridis(i as f32 / (width.max(2) - 1) as f32);
            [
                (r * 255.0).round() as u8,
                (g * 255.0).round() as u8,
                (b * 255.0).round() as u8,
                255,
            ]
        })
        .collect()
}

/// "Nice" tick values (1, 2 or 5 times a power of ten) covering `0..=max`, at most `count` + 1.
pub fn legend_ticks(max: f64, count: usize) -> Vec<f64> {
    if !(max.is_finite() && max > 0.0) || count == 0 {
        return vec![0.0];
    }
    let raw = max / count as f64;
    let power = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 5.0, 10.0]
        .into_iter()
        .map(|m| m * power)
        .find(|s| *s >= raw)
        .unwrap_or(10.0 * power);
    (0..)
        .map(|i| i as f64 * step)
        .take_while(|v| *v <= max * (1.0 + 1e-9))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn relative_luminance([r, g, b]: [f32; 3]) -> f32 {
        let lin = |c: f32| {
            if c <= 0.04045 {
                c / 12.92
            } else {
                ((c + 0.055) / 1.055).powf(2.4)
            }
        };
        0.2126 * lin(r) + 0.7152 * lin(g) + 0.0722 * lin(b)
    }

    #[test]
    fn ends_match_the_keys_and_lightness_rises_monotonically() {
        assert_eq!(
            viridis(0.0),
            [
                0x44 as f32 / 255.0,
                0x01 as f32 / 255.0,
                0x54 as f32 / 255.0
            ]
        );
        assert_eq!(
            viridis(1.0),
            [
                0xfd as f32 / 255.0,
                0xe7 as f32 / 255.0,
                0x25 as f32 / 255.0
            ]
        );
        assert_eq!(viridis(-3.0), viridis(0.0));
        assert_eq!(viridis(f32::NAN), viridis(0.0));
        let mut previous = -1.0;
        for i in 0..=1000 {
            let l = relative_luminance(viridis(i as f32 / 1000.0));
            assert!(l > previous, "luminance falls at {i}");
            previous = l;
        }
    }

    #[test]
    fn ticks_are_round_and_cover_the_range() {
        assert_eq!(legend_ticks(1.0, 4), vec![0.0, 0.5, 1.0]);
        assert_eq!(legend_ticks(0.0037, 4), vec![0.0, 0.001, 0.002, 0.003]);
        assert_eq!(legend_ticks(f64::NAN, 4), vec![0.0]);
        let t = legend_ticks(73.0, 5);
        assert_eq!(t, vec![0.0, 20.0, 40.0, 60.0]);
    }
}
