//! The file formats and how a path names one (its extension).

use super::IoError;
use std::path::Path;

/// A mesh file format, chosen from the file extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Format {
    /// Wavefront OBJ (text).
    Obj,
    /// glTF 2.0 JSON (`.gltf`) with external or embedded (data: URI) buffers.
    Gltf,
    /// glTF 2.0 binary container (`.glb`).
    Glb,
    /// Stanford PLY, ASCII or binary (either endianness); written as binary little endian.
    Ply,
    /// STL, ASCII or binary; written as binary.
    Stl,
    /// Object File Format (text).
    Off,
}

impl Format {
    /// Every supported format.
    pub const ALL: [Format; 6] = [
        Format::Obj,
        Format::Gltf,
        Format::Glb,
        Format::Ply,
        Format::Stl,
        Format::Off,
    ];

    /// The format for a file extension (case-insensitive, without the dot).
    pub fn from_extension(extension: &str) -> Option<Format> {
        let lower = extension.to_ascii_lowercase();
        Format::ALL
            .into_iter()
            .find(|format| format.extension() == lower)
    }

    /// The format for a path, from its extension.
    pub fn from_path(path: &Path) -> Option<Format> {
        path.extension()
            .and_then(|e| e.to_str())
            .and_then(Format::from_extension)
    }

    /// The usual extension, lower case, without the dot.
    pub fn extension(self) -> &'static str {
        match self {
            Format::Obj => "obj",
            Format::Gltf => "gltf",
            Format::Glb => "glb",
            Format::Ply => "ply",
            Format::Stl => "stl",
            Format::Off => "off",
        }
    }
}

impl std::fmt::Display for Format {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Format::Obj => "OBJ",
            Format::Gltf => "glTF",
            Format::Glb => "GLB",
            Format::Ply => "PLY",
            Format::Stl => "STL",
            Format::Off => "OFF",
        })
    }
}

/// The format a path's extension names, or the error that says it names none.
pub(crate) fn format_of(path: &Path) -> Result<Format, IoError> {
    Format::from_path(path).ok_or_else(|| IoError::UnknownFormat {
        path: path.to_owned(),
        extension: path
            .extension()
            .map(|e| e.to_string_lossy().into_owned())
            .unwrap_or_default(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn format_from_path_is_case_insensitive_and_rejects_unknown() {
        assert_eq!(Format::from_path(Path::new("a/b.OBJ")), Some(Format::Obj));
        assert_eq!(Format::from_path(Path::new("x.glb")), Some(Format::Glb));
        assert_eq!(Format::from_path(Path::new("x.Ply")), Some(Format::Ply));
        assert_eq!(Format::from_path(Path::new("x.txt")), None);
        assert_eq!(Format::from_path(Path::new("noext")), None);
        let err = crate::io::load(Path::new("/nowhere/mesh.xyz")).unwrap_err();
        assert!(err.to_string().starts_with("/nowhere/mesh.xyz: "), "{err}");
        assert!(err.to_string().contains("xyz"), "{err}");
    }
}
