//! Saving a bare mesh: to a path (atomically) or to any writer, after refusing a mesh no reader
//! could load back.

use super::format::format_of;
use super::{atomic, gltf, obj, off, ply, stl, Format, IoError};
use crate::mesh::TriMesh;
use std::path::Path;

/// Save a mesh; the format comes from the extension. The write is atomic: on any error nothing
/// is left behind and an existing file is unchanged. A `.gltf` also writes `<stem>.bin` beside it.
pub fn save(path: impl AsRef<Path>, mesh: &TriMesh) -> Result<(), IoError> {
    let path = path.as_ref();
    save_as(path, mesh, format_of(path)?)
}

/// Save in an explicit format, whatever the extension.
pub fn save_as(path: impl AsRef<Path>, mesh: &TriMesh, format: Format) -> Result<(), IoError> {
    let path = path.as_ref();
    check_writable(mesh, path)?;
    match format {
        Format::Obj => atomic::write(path, |w| obj::write(w, mesh)),
        Format::Glb => atomic::write(path, |w| gltf::write_glb(w, mesh)),
        Format::Gltf => gltf::write_gltf(path, mesh),
        Format::Ply => atomic::write(path, |w| ply::write(w, mesh)),
        Format::Stl => atomic::write(path, |w| stl::write(w, mesh)),
        Format::Off => atomic::write(path, |w| off::write(w, mesh)),
    }
}

/// Write a mesh in `format` to any writer (standard output, a socket, a buffer in memory). A
/// `.gltf` written this way embeds its buffer as a base64 data: URI (there is no folder for a
/// `.bin`). Not atomic: the writer is the caller's. Errors name the output "the output".
///
/// ```
/// use fairmesh::io::{write_to, Format};
/// let triangle = fairmesh::TriMesh::new(vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], vec![[0, 1, 2]]);
/// let mut text = Vec::new();
/// write_to(&mut text, &triangle, Format::Obj)?;
/// assert!(String::from_utf8_lossy(&text).contains("f 1 2 3"));
/// # Ok::<(), fairmesh::io::IoError>(())
/// ```
pub fn write_to(
    mut writer: impl std::io::Write,
    mesh: &TriMesh,
    format: Format,
) -> Result<(), IoError> {
    let name = Path::new("the output");
    check_writable(mesh, name)?;
    let out: &mut dyn std::io::Write = &mut writer;
    match format {
        Format::Obj => obj::write(out, mesh),
        Format::Glb => gltf::write_glb(out, mesh),
        Format::Gltf => gltf::write_gltf_embedded(out, mesh),
        Format::Ply => ply::write(out, mesh),
        Format::Stl => stl::write(out, mesh),
        Format::Off => off::write(out, mesh),
    }
    .and_then(|()| out.flush())
    .map_err(|source| IoError::Write {
        path: name.to_owned(),
        source,
    })
}

/// Refuse meshes that no reader could load back: no triangles, NaN/inf, indices out of range.
pub(super) fn check_writable(mesh: &TriMesh, path: &Path) -> Result<(), IoError> {
    let refuse = |message: String| IoError::Refused {
        path: path.to_owned(),
        message,
    };
    if mesh.triangles.is_empty() {
        return Err(refuse("the mesh has no triangles".into()));
    }
    if let Some(v) = mesh.first_non_finite_vertex() {
        return Err(refuse(format!(
            "vertex {v} has a non-finite coordinate {:?}",
            mesh.positions[v]
        )));
    }
    let n = mesh.positions.len();
    if let Some(f) = mesh
        .triangles
        .iter()
        .position(|t| t.iter().any(|&v| v as usize >= n))
    {
        return Err(refuse(format!(
            "triangle {f} {:?} refers to a vertex out of range (there are {n} vertices)",
            mesh.triangles[f]
        )));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn save_refuses_bad_meshes_before_writing() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("bad.obj");
        let nan = TriMesh::new(
            vec![[0.0, 0.0, 0.0], [1.0, f32::NAN, 0.0], [0.0, 1.0, 0.0]],
            vec![[0, 1, 2]],
        );
        let err = save(&path, &nan).unwrap_err();
        assert!(err.to_string().contains("vertex 1"), "{err}");
        let out_of_range = TriMesh::new(vec![[0.0; 3]; 3], vec![[0, 1, 3]]);
        assert!(save(&path, &out_of_range).is_err());
        assert!(save(&path, &TriMesh::default()).is_err());
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
    }
}
