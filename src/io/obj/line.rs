//! What the readers of a kept OBJ share: a line without its ending, a `v` line's position, a
//! corner's vertex and texture coordinate indices, the rest of a line after its keyword.

/// The parts of a line: its text without the line ending, and the ending (`\n`, `\r\n` or none).
pub(super) fn split_ending(line: &[u8]) -> (&[u8], &[u8]) {
    let body = line.strip_suffix(b"\n").unwrap_or(line);
    let body = body.strip_suffix(b"\r").unwrap_or(body);
    line.split_at(body.len())
}

/// The position a `v` line gives (w divided out), as the reader reads it; `None` if unreadable.
pub(super) fn vertex_of<'a>(words: impl Iterator<Item = &'a [u8]>) -> Option<[f32; 3]> {
    let mut values = [0f32; 6];
    let mut count = 0;
    for token in words {
        *values.get_mut(count)? = crate::io::text::parse_f32(token)?;
        count += 1;
    }
    let p = [values[0], values[1], values[2]];
    match count {
        3 | 6 => Some(p),
        4 if values[3] != 0.0 => Some(p.map(|c| c / values[3])),
        _ => None,
    }
}

/// The 0-based index an OBJ index token refers to, given how many items came before its line.
pub(super) fn resolve(token: &[u8], before: usize) -> Option<usize> {
    let index = crate::io::text::parse_i64(token)?;
    match index {
        i if i > 0 => usize::try_from(i - 1).ok(),
        i if i < 0 => usize::try_from(before as i64 + i).ok(),
        _ => None,
    }
}

/// A face corner's vertex and texture coordinate (`v/vt`, `v/vt/vn`; relative indices resolved
/// against the `vertices` and `texture_coordinates` read so far), the coordinate only when it
/// is one of those.
pub(super) fn vertex_and_uv(
    corner: &[u8],
    vertices: usize,
    texture_coordinates: usize,
) -> (Option<usize>, Option<usize>) {
    let mut parts = corner.split(|&b| b == b'/');
    let vertex = parts.next().and_then(|t| resolve(t, vertices));
    let uv = parts
        .next()
        .filter(|t| !t.is_empty())
        .and_then(|t| resolve(t, texture_coordinates))
        .filter(|&t| t < texture_coordinates);
    (vertex, uv)
}

/// The rest of a line after its keyword (`o`, `g`, `usemtl`, `mtllib`, `map_Kd`), words joined by
/// one space; `None` when empty.
pub(super) fn rest_of<'a>(words: impl Iterator<Item = &'a [u8]>) -> Option<String> {
    let words: Vec<String> = words
        .map(|w| String::from_utf8_lossy(w).into_owned())
        .collect();
    (!words.is_empty()).then(|| words.join(" "))
}
