//! Loading: reading a file (or bytes, or a reader), parsing it in its format, and finishing the
//! mesh ([`super::finish`]) with the [`Source`] that keeps what it was read from.

use super::finish::{finish_with_map, LoadOptions, Loaded};
use super::format::format_of;
use super::origin::Origin;
use super::source::SourceData;
use super::{gltf, obj, off, ply, stl, Format, IoError, Parsed, Source};
use crate::mesh::TriMesh;
use std::borrow::Cow;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Load a mesh, welded and cleaned, with default options; the format comes from the extension.
///
/// ```
/// let path = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/bunny00.obj");
/// let loaded = fairmesh::io::load(path)?;
/// assert_eq!(loaded.mesh.vertex_count(), 37_706);
/// assert_eq!(loaded.mesh.face_count(), 75_408);
/// assert!(loaded.topology.boundary_loops.is_empty()); // a closed mesh
/// # Ok::<(), fairmesh::io::IoError>(())
/// ```
pub fn load(path: impl AsRef<Path>) -> Result<Loaded, IoError> {
    load_with(path, &LoadOptions::default())
}

/// Load a mesh; the format comes from the extension.
pub fn load_with(path: impl AsRef<Path>, options: &LoadOptions) -> Result<Loaded, IoError> {
    let path = path.as_ref();
    let format = format_of(path)?;
    let bytes = super::files::read(path).map_err(|source| IoError::Read {
        path: path.to_owned(),
        source,
    })?;
    let base_dir = path.parent().map(Path::to_path_buf);
    load_bytes_impl(Cow::Owned(bytes), format, path, base_dir, options)
}

/// Parse a mesh from bytes in memory. `name` stands for the path in error messages (a file name,
/// or e.g. "dropped file"). A glTF that refers to external buffer files cannot be loaded this way
/// (there is no directory to resolve them in); embedded (data: URI) buffers and GLB work.
pub fn load_from_bytes(
    bytes: &[u8],
    format: Format,
    name: &str,
    options: &LoadOptions,
) -> Result<Loaded, IoError> {
    load_bytes_impl(Cow::Borrowed(bytes), format, Path::new(name), None, options)
}

/// Read a mesh in `format` from any reader (standard input, an archive entry, a socket). `name`
/// stands for the path in error messages; as with [`load_from_bytes`], a glTF's external buffers
/// cannot be resolved.
pub fn load_from_reader(
    mut reader: impl std::io::Read,
    format: Format,
    name: &str,
    options: &LoadOptions,
) -> Result<Loaded, IoError> {
    let mut bytes = Vec::new();
    reader
        .read_to_end(&mut bytes)
        .map_err(|source| IoError::Read {
            path: PathBuf::from(name),
            source,
        })?;
    load_bytes_impl(Cow::Owned(bytes), format, Path::new(name), None, options)
}

fn load_bytes_impl(
    bytes: Cow<'_, [u8]>,
    format: Format,
    path: &Path,
    base_dir: Option<PathBuf>,
    options: &LoadOptions,
) -> Result<Loaded, IoError> {
    if bytes.is_empty() {
        return Err(IoError::invalid(path, "the file is empty"));
    }
    let bytes = without_byte_order_mark(bytes, format, path)?;
    let (mesh, parse_warnings, mut data) = parse(&bytes, format, path, base_dir.as_deref())?;
    check_parsed(&mesh, path)?;
    // The text and PLY sources are the file itself: kept as read, not copied, when it came from
    // a file.
    match format {
        Format::Obj => data = SourceData::Obj(bytes.into_owned()),
        Format::Ply if ply::can_write_back(&bytes) => data = SourceData::Ply(bytes.into_owned()),
        _ => drop(bytes),
    }
    let raw_vertices = mesh.positions.len();
    let (mut loaded, raw_to_welded) = finish_with_map(mesh, options);
    loaded.source = Arc::new(Source {
        format,
        origin: Origin {
            path: path.to_owned(),
            base_dir,
            raw_to_welded,
            raw_vertices,
            welded_vertices: loaded.mesh.positions.len(),
        },
        welded_triangles: loaded.mesh.triangles.len(),
        triangle_fingerprint: loaded.source.triangle_fingerprint,
        data,
    });
    if loaded.mesh.triangles.is_empty() {
        return Err(IoError::invalid(
            path,
            format!(
                "no triangles left: all {} triangles repeat a vertex",
                loaded.report.removed_degenerate_faces
            ),
        ));
    }
    let mut warnings = parse_warnings;
    warnings.append(&mut loaded.report.warnings);
    loaded.report.warnings = warnings;
    Ok(loaded)
}

/// The mesh and warnings of `format`'s parser, and what it keeps of the file as [`SourceData`].
fn parse(
    bytes: &[u8],
    format: Format,
    path: &Path,
    base_dir: Option<&Path>,
) -> Result<(TriMesh, Vec<String>, SourceData), IoError> {
    Ok(match format {
        Format::Obj => with_data(obj::parse(bytes, path)?, |()| SourceData::Plain),
        Format::Gltf | Format::Glb => with_data(gltf::parse(bytes, path, base_dir)?, |gltf| {
            SourceData::Gltf(Box::new(gltf))
        }),
        Format::Ply => with_data(ply::parse(bytes, path)?, |()| SourceData::Plain),
        Format::Stl => with_data(stl::parse(bytes, path)?, |stl| {
            SourceData::Stl(Box::new(stl))
        }),
        Format::Off => with_data(off::parse(bytes, path)?, |()| SourceData::Plain),
    })
}

/// A parser's mesh and warnings, and what it kept (made [`SourceData`] by `wrap`), or else what
/// the file holds that is not kept.
fn with_data<K>(
    parsed: Parsed<K>,
    wrap: impl FnOnce(K) -> SourceData,
) -> (TriMesh, Vec<String>, SourceData) {
    let data = match parsed.kept {
        Some(kept) => wrap(kept),
        None if parsed.unkept.is_empty() => SourceData::Plain,
        None => SourceData::Unkept(parsed.unkept),
    };
    (parsed.mesh, parsed.warnings, data)
}

/// A safety net behind the parsers' own checks (which name the line or byte): `finish` needs
/// indices in range and finite positions.
fn check_parsed(mesh: &TriMesh, path: &Path) -> Result<(), IoError> {
    if mesh.triangles.is_empty() {
        return Err(IoError::invalid(path, "the file has no triangles"));
    }
    if let Some(v) = mesh.first_non_finite_vertex() {
        return Err(IoError::invalid(
            path,
            format!("vertex {v} has a NaN or infinite coordinate"),
        ));
    }
    let n = mesh.positions.len();
    if let Some((f, t)) = mesh
        .triangles
        .iter()
        .enumerate()
        .find(|(_, t)| t.iter().any(|&v| v as usize >= n))
    {
        return Err(IoError::invalid(
            path,
            format!("triangle {f} {t:?} refers to a vertex out of range (there are {n} vertices)"),
        ));
    }
    Ok(())
}

/// A text file (OBJ, OFF, glTF JSON, a PLY header) that starts with a UTF-8 byte order mark, as
/// Windows editors write, is read without it (in an OBJ the first line's keyword would not be
/// recognised, and a vertex would be lost); one in UTF-16 is refused with an error saying so
/// (every line would read as not UTF-8). Binary STL and GLB are not text: their first bytes are
/// data.
fn without_byte_order_mark<'a>(
    bytes: Cow<'a, [u8]>,
    format: Format,
    path: &Path,
) -> Result<Cow<'a, [u8]>, IoError> {
    const UTF8: &[u8] = b"\xEF\xBB\xBF";
    if !matches!(
        format,
        Format::Obj | Format::Off | Format::Gltf | Format::Ply
    ) {
        return Ok(bytes);
    }
    if bytes.starts_with(b"\xFE\xFF") || bytes.starts_with(b"\xFF\xFE") {
        return Err(IoError::invalid(
            path,
            "the file is UTF-16 text (it starts with a UTF-16 byte order mark); fairmesh reads \
             UTF-8 or ASCII: save it again as UTF-8",
        ));
    }
    Ok(match bytes {
        Cow::Borrowed(b) => Cow::Borrowed(b.strip_prefix(UTF8).unwrap_or(b)),
        Cow::Owned(mut b) => {
            if b.starts_with(UTF8) {
                b.drain(..UTF8.len());
            }
            Cow::Owned(b)
        }
    })
}
