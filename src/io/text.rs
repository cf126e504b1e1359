//! Helpers shared by the text parsers (OBJ line finding, PLY ASCII, STL ASCII, OFF): lines with
//! 1-based numbers over raw bytes (files need not be UTF-8; only numbers are interpreted),
//! whitespace tokens, number parsing that rejects garbage, and short quotes for error messages.

/// Lines of `bytes` with their 1-based numbers; the `\n` is removed, and a `\r` before it.
pub(crate) fn lines(bytes: &[u8]) -> impl Iterator<Item = (usize, &[u8])> {
    let mut rest = bytes;
    let mut number = 0usize;
    std::iter::from_fn(move || {
        if rest.is_empty() {
            return None;
        }
        number += 1;
        let (line, tail) = match rest.iter().position(|&b| b == b'\n') {
            Some(end) => (&rest[..end], &rest[end + 1..]),
            None => (rest, &rest[rest.len()..]),
        };
        rest = tail;
        let line = line.strip_suffix(b"\r").unwrap_or(line);
        Some((number, line))
    })
}

/// The line without a `#` comment.
pub(crate) fn strip_comment(line: &[u8]) -> &[u8] {
    match line.iter().position(|&b| b == b'#') {
        Some(hash) => &line[..hash],
        None => line,
    }
}

/// Whitespace-separated tokens of a line.
pub(crate) fn tokens(line: &[u8]) -> impl Iterator<Item = &[u8]> {
    line.split(|b| b.is_ascii_whitespace())
        .filter(|t| !t.is_empty())
}

pub(crate) fn parse_f32(token: &[u8]) -> Option<f32> {
    std::str::from_utf8(token).ok()?.parse().ok()
}

pub(crate) fn parse_f64(token: &[u8]) -> Option<f64> {
    std::str::from_utf8(token).ok()?.parse().ok()
}

pub(crate) fn parse_i64(token: &[u8]) -> Option<i64> {
    std::str::from_utf8(token).ok()?.parse().ok()
}

/// A token quoted for an error message, cut to 40 characters.
pub(crate) fn quote(token: &[u8]) -> String {
    let text = String::from_utf8_lossy(token);
    let short: String = text.chars().take(40).collect();
    if short.len() < text.len() {
        format!("\"{short}...\"")
    } else {
        format!("\"{short}\"")
    }
}

/// "1 polyline (l)", "3 polylines (l)": `count` things, `one` and `many` naming one and several.
pub(crate) fn counted(count: usize, one: &str, many: &str) -> String {
    match count {
        1 => format!("1 {one}"),
        n => format!("{n} {many}"),
    }
}

/// "1 polyline (l) was skipped", "3 polylines (l) were skipped": a reader's warning about what
/// it left out, `one` and `many` naming one and several of them.
pub(crate) fn skipped(count: usize, one: &str, many: &str) -> String {
    let verb = if count == 1 { "was" } else { "were" };
    format!("{} {verb} skipped", counted(count, one, many))
}

/// The warning for faces a reader skipped because they have fewer than three corners.
pub(crate) fn short_faces_skipped(count: usize) -> String {
    skipped(
        count,
        "face with fewer than 3 corners",
        "faces with fewer than 3 corners",
    )
}

/// "NaN" or "infinite", for messages about a non-finite coordinate.
pub(crate) fn non_finite_kind(value: f32) -> &'static str {
    if value.is_nan() {
        "a NaN"
    } else {
        "an infinite"
    }
}

/// "a", "a and b", "a, b and c".
pub(crate) fn and_list(items: &[&str]) -> String {
    match items {
        [] => String::new(),
        [one] => one.to_string(),
        [rest @ .., last] => format!("{} and {last}", rest.join(", ")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lines_are_numbered_and_strip_crlf() {
        let got: Vec<(usize, &[u8])> = lines(b"a\r\nb\n\nc").collect();
        assert_eq!(
            got,
            vec![
                (1, &b"a"[..]),
                (2, &b"b"[..]),
                (3, &b""[..]),
                (4, &b"c"[..])
            ]
        );
        assert_eq!(tokens(b"  1 \t 2  ").collect::<Vec<_>>(), vec![b"1", b"2"]);
        assert_eq!(parse_f32(b"1e3"), Some(1000.0));
        assert_eq!(parse_f32(b"1x"), None);
        assert_eq!(strip_comment(b"1 2 # x"), b"1 2 ");
    }
}
