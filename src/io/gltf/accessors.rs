//! One accessor element's components as bytes: the accessor's [`Layout`], decoding, and encoding
//! (32-bit floats, or integers, normalized or not, under KHR_mesh_quantization: quantized, with
//! directions rounded to stay of unit length).

use glam::DVec3;

/// The bytes behind one accessor: buffer, offset of element 0, stride, component type and size,
/// components per element, normalized, count.
#[derive(Clone, Copy, Debug)]
pub(super) struct Layout {
    pub(super) buffer: usize,
    pub(super) start: usize,
    pub(super) stride: usize,
    pub(super) component: u64,
    pub(super) size: usize,
    pub(super) components: usize,
    pub(super) normalized: bool,
    pub(super) count: usize,
}

pub(super) fn decode(layout: &Layout, b: &[u8]) -> f32 {
    macro_rules! get {
        ($t:ty) => {
            <$t>::from_le_bytes(b.try_into().unwrap_or_default())
        };
    }
    let n = layout.normalized;
    match layout.component {
        5126 => get!(f32),
        5120 if n => (get!(i8) as f32 / 127.0).max(-1.0),
        5121 if n => get!(u8) as f32 / 255.0,
        5122 if n => (get!(i16) as f32 / 32767.0).max(-1.0),
        5123 if n => get!(u16) as f32 / 65535.0,
        5125 if n => (get!(u32) as f64 / u32::MAX as f64) as f32,
        5120 => get!(i8) as f32,
        5121 => get!(u8) as f32,
        5122 => get!(i16) as f32,
        5123 => get!(u16) as f32,
        _ => get!(u32) as f32,
    }
}

/// What a stored integer of an integer component type is multiplied by to give its value (1
/// unless normalized).
fn integer_scale(layout: &Layout) -> f64 {
    match (layout.normalized, layout.component) {
        (false, _) => 1.0,
        (true, 5120) => 127.0,
        (true, 5121) => 255.0,
        (true, 5122) => 32767.0,
        (true, 5123) => 65535.0,
        (true, _) => u32::MAX as f64,
    }
}

/// The least and greatest stored integer of an integer component type.
fn integer_range(layout: &Layout) -> (f64, f64) {
    match layout.component {
        5120 => (i8::MIN as f64, i8::MAX as f64),
        5121 => (0.0, u8::MAX as f64),
        5122 => (i16::MIN as f64, i16::MAX as f64),
        5123 => (0.0, u16::MAX as f64),
        _ => (0.0, u32::MAX as f64),
    }
}

/// The integer nearest `value` in an integer component type, before it is held to the type's
/// range.
fn unclamped(layout: &Layout, value: f32) -> f64 {
    (value as f64 * integer_scale(layout)).round()
}

/// The stored (integer) value for `value` in an integer component type.
fn quantize(layout: &Layout, value: f32) -> f64 {
    let (lo, hi) = integer_range(layout);
    unclamped(layout, value).clamp(lo, hi)
}

/// Whether `value` can be stored in the layout's component type without being clamped.
pub(super) fn fits(layout: &Layout, value: f32) -> bool {
    let (lo, hi) = integer_range(layout);
    layout.component == FLOAT || (lo..=hi).contains(&unclamped(layout, value))
}

/// The stored integers for a direction (a normal, a tangent's first three components) in a
/// normalized integer type: of the roundings of each component down or up, one whose decoded
/// length is within [`LENGTH_TOLERANCE`] of the length it should have and whose direction is
/// nearest, or the one with the nearest length if none is. The length it should have is 1 for
/// a direction within 0.01 of it (a unit vector as integers store it: the file's own normal,
/// turned, keeps the few thousandths its integers were off), its own otherwise (a file that
/// stores longer or shorter vectors keeps them so). (Rounding each component to the nearest
/// integer leaves unit normals up to 0.007 off unit length in 8 bits, which glTF validators
/// reject: their tolerance is 0.00465.)
pub(super) fn quantize_direction(layout: &Layout, direction: [f32; 3]) -> [f64; 3] {
    let scale = integer_scale(layout);
    let (lo, hi) = integer_range(layout);
    let wanted = DVec3::from(direction.map(f64::from));
    let length = match wanted.length() {
        unit if (unit - 1.0).abs() < 0.01 => 1.0,
        other => other,
    };
    let mut best = ([0.0; 3], (true, f64::INFINITY));
    for corner in 0..8 {
        let q: [f64; 3] = std::array::from_fn(|c| {
            let x = wanted[c] * scale;
            let q = if corner >> c & 1 == 0 {
                x.floor()
            } else {
                x.ceil()
            };
            q.clamp(lo, hi)
        });
        // As a reader decodes it (a signed -128 reads as -1, like -127).
        let decoded = DVec3::from(q.map(|q| (q / scale).max(-1.0)));
        let length_off = (decoded.length() - length).abs();
        let turn = 1.0 - decoded.normalize_or_zero().dot(wanted.normalize_or_zero());
        // Within the tolerance first (false orders before true), then the nearer direction; of
        // those outside it, the nearer length.
        let outside = length_off > LENGTH_TOLERANCE;
        let score = (outside, if outside { length_off } else { turn });
        if score < best.1 {
            best = (q, score);
        }
    }
    best.0
}

/// How far a direction written as integers may be from its own length (a normal's is 1; the
/// glTF validator accepts 0.00465).
const LENGTH_TOLERANCE: f64 = 0.004;

/// The component type of 32-bit floats.
pub(super) const FLOAT: u64 = 5126;

pub(super) fn encode(layout: &Layout, value: f32, out: &mut [u8]) {
    if layout.component == FLOAT {
        out.copy_from_slice(&value.to_le_bytes());
        return;
    }
    store(layout, quantize(layout, value), out);
}

/// Writes the stored integer `q` (already in the type's range) in the layout's component type.
pub(super) fn store(layout: &Layout, q: f64, out: &mut [u8]) {
    match layout.component {
        5120 => out.copy_from_slice(&(q as i8).to_le_bytes()),
        5121 => out.copy_from_slice(&(q as u8).to_le_bytes()),
        5122 => out.copy_from_slice(&(q as i16).to_le_bytes()),
        5123 => out.copy_from_slice(&(q as u16).to_le_bytes()),
        _ => out.copy_from_slice(&(q as u32).to_le_bytes()),
    }
}

/// How the specification names a layout's component type, for messages.
pub(super) fn component_name(layout: &Layout) -> String {
    let kind = match layout.component {
        5120 => "signed 8-bit",
        5121 => "unsigned 8-bit",
        5122 => "signed 16-bit",
        5123 => "unsigned 16-bit",
        5125 => "unsigned 32-bit",
        _ => "32-bit float",
    };
    if layout.normalized {
        format!("normalized {kind} integers")
    } else if layout.component == FLOAT {
        format!("{kind}s")
    } else {
        format!("{kind} integers")
    }
}
