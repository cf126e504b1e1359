//! Vertex lists: a text file of 0-based vertex indices in a mesh file's own vertex order, one a
//! line; blank lines and `#` comments are allowed (the CLI's `--mask`). Loading welds vertices
//! (an OBJ or glTF splits them at seams), so [`loaded_vertices`] translates the file's indices to
//! the loaded mesh's through [`Source::loaded_vertex`]. Errors name the list and the line.

use super::Source;
use std::path::{Path, PathBuf};

/// What is wrong with a vertex list.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum VertexListError {
    #[error("{}: cannot read the vertex list: {source}", path.display())]
    Read {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{}, line {line}: {message}", path.display())]
    Line {
        path: PathBuf,
        line: usize,
        message: String,
    },
}

/// Parses a vertex list: (line number, 1-based; vertex index) per entry. `path` names the list
/// in errors.
pub fn parse_vertex_list(text: &str, path: &Path) -> Result<Vec<(usize, usize)>, VertexListError> {
    let mut vertices = Vec::new();
    for (number, line) in text.lines().enumerate() {
        let content = line.split('#').next().unwrap_or("").trim();
        if content.is_empty() {
            continue;
        }
        let index = content
            .parse::<usize>()
            .map_err(|_| VertexListError::Line {
                path: path.to_owned(),
                line: number + 1,
                message: format!(
                    "`{content}` is not a vertex index (expected one 0-based whole number a line)"
                ),
            })?;
        vertices.push((number + 1, index));
    }
    Ok(vertices)
}

/// Reads and parses the vertex list at `path` ([`parse_vertex_list`]).
pub fn read_vertex_list(path: &Path) -> Result<Vec<(usize, usize)>, VertexListError> {
    let bytes = std::fs::read(path).map_err(|source| VertexListError::Read {
        path: path.to_owned(),
        source,
    })?;
    let text = String::from_utf8(bytes).map_err(|e| VertexListError::Line {
        path: path.to_owned(),
        line: 1 + e.as_bytes()[..e.utf8_error().valid_up_to()]
            .iter()
            .filter(|&&b| b == b'\n')
            .count(),
        message: "the line is not text (UTF-8)".into(),
    })?;
    parse_vertex_list(&text, path)
}

/// The loaded vertices that the file's vertices `file_vertices` (0-based, in the file's order,
/// as [`read_vertex_list`] gives them) became; a vertex no triangle uses was dropped on loading
/// and gives none. `path` names the list in errors: an index beyond the file's vertices is an
/// error naming its line.
pub fn loaded_vertices(
    source: &Source,
    file_vertices: &[(usize, usize)],
    path: &Path,
) -> Result<Vec<usize>, VertexListError> {
    let file_count = source.file_vertex_count();
    let mut loaded = Vec::with_capacity(file_vertices.len());
    for &(line, index) in file_vertices {
        if index >= file_count {
            return Err(VertexListError::Line {
                path: path.to_owned(),
                line,
                message: format!(
                    "vertex {index} is out of range: the mesh file has {file_count} vertices \
                     (indices are 0-based)"
                ),
            });
        }
        loaded.extend(source.loaded_vertex(index));
    }
    Ok(loaded)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn vertex_lists_skip_comments_and_name_the_bad_line() {
        let path = Path::new("region.txt");
        let list = parse_vertex_list("# painted\n3\n\n 7  # tip\n0\n", path).unwrap();
        assert_eq!(list, vec![(2, 3), (4, 7), (5, 0)]);
        let error = parse_vertex_list("1\n2\nseven\n", path).unwrap_err();
        let message = error.to_string();
        assert!(message.starts_with("region.txt, line 3:"), "{message}");
        assert!(message.contains("`seven`"), "{message}");
        assert!(parse_vertex_list("-1\n", path).is_err());
    }
}
