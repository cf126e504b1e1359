//! The accessors a glTF scene is read from (POSITION and indices), with every offset and length
//! checked against the buffer view and buffer: the `gltf` crate's readers trust the file.

use ::gltf::accessor::{DataType, Dimensions};
use std::borrow::Cow;

/// The bytes of an accessor's elements, checked: `(data, stride, element size)`, `data` starting
/// at the first element and holding all `count` of them.
fn accessor_bytes<'a>(
    accessor: &::gltf::Accessor,
    buffers: &'a [Cow<'a, [u8]>],
) -> Result<(&'a [u8], usize, usize), String> {
    if accessor.sparse().is_some() {
        return Err("sparse accessors are not supported".into());
    }
    let view = accessor
        .view()
        .ok_or("has no bufferView (all zeros), which gives no usable geometry")?;
    let buffer = buffers
        .get(view.buffer().index())
        .ok_or("its buffer does not exist")?;
    let element = accessor
        .data_type()
        .size()
        .checked_mul(accessor.dimensions().multiplicity())
        .ok_or("element size overflows")?;
    let stride = view.stride().unwrap_or(element);
    if stride < element {
        return Err(format!(
            "buffer view {} has byteStride {stride}, less than the element size {element}",
            view.index()
        ));
    }
    let view_end = view
        .offset()
        .checked_add(view.length())
        .filter(|&end| end <= buffer.len())
        .ok_or_else(|| {
            format!(
                "buffer view {} (bytes {}..+{}) runs past the end of buffer {} ({} bytes)",
                view.index(),
                view.offset(),
                view.length(),
                view.buffer().index(),
                buffer.len()
            )
        })?;
    let view_bytes = buffer.get(view.offset()..view_end).unwrap_or_default();
    let count = accessor.count();
    let needed = match count {
        0 => 0,
        n => (n - 1)
            .checked_mul(stride)
            .and_then(|b| b.checked_add(element))
            .and_then(|b| b.checked_add(accessor.offset()))
            .ok_or("its size overflows")?,
    };
    if needed > view_bytes.len() {
        return Err(format!(
            "{count} elements at byteOffset {} need {needed} bytes but buffer view {} has {}",
            accessor.offset(),
            view.index(),
            view_bytes.len()
        ));
    }
    let data = view_bytes
        .get(accessor.offset().min(needed)..needed)
        .unwrap_or_default();
    Ok((data, stride, element))
}

fn component_f32(kind: DataType, normalized: bool, b: &[u8]) -> Option<f32> {
    macro_rules! get {
        ($t:ty, $n:literal) => {
            <$t>::from_le_bytes(b.get(..$n)?.try_into().ok()?)
        };
    }
    Some(match (kind, normalized) {
        (DataType::F32, _) => get!(f32, 4),
        (DataType::I8, true) => (get!(i8, 1) as f32 / 127.0).max(-1.0),
        (DataType::U8, true) => get!(u8, 1) as f32 / 255.0,
        (DataType::I16, true) => (get!(i16, 2) as f32 / 32767.0).max(-1.0),
        (DataType::U16, true) => get!(u16, 2) as f32 / 65535.0,
        (DataType::U32, true) => (get!(u32, 4) as f64 / u32::MAX as f64) as f32,
        (DataType::I8, false) => get!(i8, 1) as f32,
        (DataType::U8, false) => get!(u8, 1) as f32,
        (DataType::I16, false) => get!(i16, 2) as f32,
        (DataType::U16, false) => get!(u16, 2) as f32,
        (DataType::U32, false) => get!(u32, 4) as f32,
    })
}

pub(super) fn read_positions(
    accessor: &::gltf::Accessor,
    buffers: &[Cow<[u8]>],
) -> Result<Vec<[f32; 3]>, String> {
    if accessor.dimensions() != Dimensions::Vec3 {
        return Err(format!(
            "type is {:?}, expected VEC3",
            accessor.dimensions()
        ));
    }
    let (data, stride, _) = accessor_bytes(accessor, buffers)?;
    let kind = accessor.data_type();
    let size = kind.size();
    let normalized = accessor.normalized();
    let mut positions = Vec::with_capacity(accessor.count());
    for k in 0..accessor.count() {
        let mut p = [0f32; 3];
        for (axis, c) in p.iter_mut().enumerate() {
            *c = data
                .get(k * stride + axis * size..)
                .and_then(|b| component_f32(kind, normalized, b))
                .ok_or_else(|| format!("element {k} is out of bounds"))?;
        }
        positions.push(p);
    }
    Ok(positions)
}

pub(super) fn read_indices(
    accessor: &::gltf::Accessor,
    buffers: &[Cow<[u8]>],
) -> Result<Vec<u32>, String> {
    if accessor.dimensions() != Dimensions::Scalar {
        return Err(format!(
            "type is {:?}, expected SCALAR",
            accessor.dimensions()
        ));
    }
    let kind = accessor.data_type();
    if !matches!(kind, DataType::U8 | DataType::U16 | DataType::U32) {
        return Err(format!("component type {kind:?} is not an index type"));
    }
    let (data, stride, _) = accessor_bytes(accessor, buffers)?;
    let mut indices = Vec::with_capacity(accessor.count());
    for k in 0..accessor.count() {
        let b = data
            .get(k * stride..)
            .ok_or_else(|| format!("element {k} is out of bounds"))?;
        let index = match kind {
            DataType::U8 => b.first().map(|&x| x as u32),
            DataType::U16 => b.get(..2).map(|x| u16::from_le_bytes([x[0], x[1]]) as u32),
            _ => b
                .get(..4)
                .map(|x| u32::from_le_bytes([x[0], x[1], x[2], x[3]])),
        }
        .ok_or_else(|| format!("element {k} is out of bounds"))?;
        indices.push(index);
    }
    Ok(indices)
}
