//! Reading and writing meshes: OBJ, glTF/GLB, PLY, STL and OFF.
//!
//! `load(path)` and `save(path, mesh)` dispatch on the file extension ([`Format::from_path`]);
//! [`load_from_bytes`] parses a buffer already in memory (drag and drop, fuzzing). One file per
//! format; this file holds the dispatch, the shared checks and the post-processing.
//!
//! Choices:
//! - Files are read whole into memory and parsed from the slice: it is the fastest way for every
//!   format here and lets binary parsers check lengths before they allocate.
//! - Every parser checks what it reads (finite coordinates, indices in range, lengths) and reports
//!   the line (text formats) or byte offset / element (binary formats) at fault; [`IoError`]'s
//!   `Display` always starts with the path. No parser panics on any input (they are fuzzed, see
//!   `fuzz/`).
//! - After parsing, [`finish`] welds bit-identical positions (seams), drops degenerate triangles
//!   and unused vertices and builds the topology; non-manifold or inconsistently oriented input is
//!   loaded, with a warning in [`LoadReport::warnings`].
//! - Writes are atomic (`atomic.rs`): a temporary file beside the target is renamed into place, so a
//!   failed export never leaves a partial file or damages an existing one. Meshes with non-finite
//!   positions or out-of-range indices are refused before anything is written.

pub(crate) mod atomic;
mod carry;
mod error;
mod gltf;
mod obj;
mod off;
mod ply;
mod scene;
mod source;
mod stl;
mod text;
mod uv_follow;

pub use error::{IoError, Location};
pub use source::{SaveReport, Source};

use crate::mesh::{self, Topology, TriMesh};
use source::SourceData;
use std::borrow::Cow;
use std::path::{Path, PathBuf};
use std::sync::Arc;

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

#[derive(Clone, Debug)]
pub struct LoadOptions {
    /// Merge vertices with identical positions (seams in OBJ and glTF files, STL's unshared
    /// corners).
    pub weld: bool,
}

impl Default for LoadOptions {
    fn default() -> Self {
        Self { weld: true }
    }
}

/// What loading did to the file's data, and what is worth a warning.
#[derive(Clone, Debug, Default)]
pub struct LoadReport {
    pub welded_vertices: usize,
    pub removed_degenerate_faces: usize,
    /// Triangles with the same three corners as an earlier one (see [`mesh::clean`]).
    pub removed_repeated_faces: usize,
    pub removed_unreferenced_vertices: usize,
    pub warnings: Vec<String>,
}

/// A loaded, welded and cleaned mesh with its topology, and what it was read from.
#[derive(Clone, Debug)]
pub struct Loaded {
    pub mesh: TriMesh,
    pub topology: Topology,
    pub report: LoadReport,
    /// The file the mesh came from, kept so that [`save_with_source`] writes it back with only
    /// the positions (and what depends on them) changed.
    pub source: Arc<Source>,
}

/// What a format parser hands back: the raw mesh (indices checked, positions finite), warnings
/// about what it skipped, and what of the file is kept for writing it back.
#[derive(Debug)]
pub(crate) struct Parsed {
    pub mesh: TriMesh,
    pub warnings: Vec<String>,
    pub data: SourceData,
}

impl Parsed {
    fn new(mesh: TriMesh) -> Parsed {
        Parsed {
            mesh,
            warnings: Vec::new(),
            data: SourceData::Plain,
        }
    }
}

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
    let bytes = std::fs::read(path).map_err(|source| IoError::Read {
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
    let mut parsed = match format {
        Format::Obj => obj::parse(&bytes, path)?,
        Format::Gltf | Format::Glb => gltf::parse(&bytes, path, base_dir.as_deref())?,
        Format::Ply => ply::parse(&bytes, path)?,
        Format::Stl => stl::parse(&bytes, path)?,
        Format::Off => off::parse(&bytes, path)?,
    };
    check_parsed(&parsed.mesh, path)?;
    // The text and PLY sources are the file itself: kept as read, not copied, when it came from
    // a file.
    match format {
        Format::Obj => parsed.data = SourceData::Obj(bytes.into_owned()),
        Format::Ply if ply::can_write_back(&bytes) => {
            parsed.data = SourceData::Ply(bytes.into_owned())
        }
        _ => drop(bytes),
    }
    let raw_vertices = parsed.mesh.positions.len();
    let (mut loaded, raw_to_welded) = finish_with_map(parsed.mesh, options);
    loaded.source = Arc::new(Source {
        format,
        path: path.to_owned(),
        base_dir,
        raw_to_welded,
        raw_vertices,
        welded_vertices: loaded.mesh.positions.len(),
        welded_triangles: loaded.mesh.triangles.len(),
        triangle_fingerprint: loaded.source.triangle_fingerprint,
        data: parsed.data,
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
    let mut warnings = parsed.warnings;
    warnings.append(&mut loaded.report.warnings);
    loaded.report.warnings = warnings;
    Ok(loaded)
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

fn format_of(path: &Path) -> Result<Format, IoError> {
    Format::from_path(path).ok_or_else(|| IoError::UnknownFormat {
        path: path.to_owned(),
        extension: path
            .extension()
            .map(|e| e.to_string_lossy().into_owned())
            .unwrap_or_default(),
    })
}

/// Weld, clean and build the topology of a freshly parsed mesh. Indices must be in range and
/// positions finite (every parser checks both). Non-manifold and inconsistently oriented input
/// gets a warning in the report.
pub fn finish(mesh: TriMesh, options: &LoadOptions) -> Loaded {
    finish_with_map(mesh, options).0
}

/// [`finish`], also giving the map from the input's vertices to the welded ones (`u32::MAX` for
/// a dropped vertex), `None` when they are the same.
fn finish_with_map(mut mesh: TriMesh, options: &LoadOptions) -> (Loaded, Option<Vec<u32>>) {
    let mut report = LoadReport::default();
    let mut map = None;
    if options.weld {
        let (welded, weld_map) = mesh::weld_with_map(&mut mesh);
        report.welded_vertices = welded.merged_vertices;
        map = weld_map;
    }
    let (mut cleaned, clean_map) = mesh::clean_with_map_but_repeats(&mut mesh);
    if let Some(clean_map) = clean_map {
        map = Some(match map {
            None => clean_map,
            Some(mut map) => {
                for v in &mut map {
                    *v = clean_map[*v as usize];
                }
                map
            }
        });
    }
    // Triangles that repeat an earlier one's corners: found from the topology, which is built
    // anyway (and built again only when some go).
    let mut topology = Topology::build(&mesh);
    let repeats = std::mem::take(&mut topology.repeated_triangles);
    if !repeats.is_empty() {
        mesh::remove_triangles(&mut mesh, &repeats);
        topology = Topology::build(&mesh);
    }
    cleaned.removed_repeated_faces = repeats.len();
    report.removed_degenerate_faces = cleaned.removed_degenerate_faces;
    report.removed_repeated_faces = cleaned.removed_repeated_faces;
    if cleaned.removed_repeated_faces > 0 {
        report.warnings.push(format!(
            "{} triangles had the same three corners as another triangle and were left out of \
             the smoothing (they would be pulled to a point); written back into its own format, \
             the file keeps them",
            cleaned.removed_repeated_faces
        ));
    }
    report.removed_unreferenced_vertices = cleaned.removed_unreferenced_vertices;
    if topology.inconsistent_edges > 0 {
        // Neighbouring triangles facing opposite ways: orient each component consistently (the
        // file itself keeps its own faces when it is written back; only positions change).
        let oriented = mesh::orient_consistently(&mut mesh, &topology);
        if oriented.flipped_faces > 0 {
            report.warnings.push(format!(
                "{} triangles faced the other way from their neighbours and were flipped, in {} \
                 part(s), so that volume and normals mean something",
                oriented.flipped_faces, oriented.reoriented_components
            ));
            topology = Topology::build(&mesh);
        }
        if oriented.non_orientable_components > 0 {
            report.warnings.push(format!(
                "{} part(s) cannot be oriented (like a Moebius strip): they are faired without \
                 keeping to their normals, and their volume means nothing",
                oriented.non_orientable_components
            ));
        }
    }
    if !topology.non_manifold_edges.is_empty() {
        let [a, b] = topology.non_manifold_edges[0];
        report.warnings.push(format!(
            "{} non-manifold edges (used by more than two triangles), e.g. between vertices {a} and {b}",
            topology.non_manifold_edges.len()
        ));
    }
    if !topology.non_manifold_vertices.is_empty() {
        report.warnings.push(format!(
            "{} non-manifold vertices (their triangles do not form a single fan), e.g. vertex {}",
            topology.non_manifold_vertices.len(),
            topology.non_manifold_vertices[0]
        ));
    }
    if topology.inconsistent_edges > 0 {
        report.warnings.push(format!(
            "{} edges where neighbouring triangles have opposite orientations",
            topology.inconsistent_edges
        ));
    }
    let source = Arc::new(Source::plain(&mesh));
    (
        Loaded {
            mesh,
            topology,
            report,
            source,
        },
        map,
    )
}

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

/// Save `mesh` into what it was loaded from: to the same family of format (OBJ, PLY, glTF/GLB)
/// the source file comes back with only the positions and what depends on them changed (see
/// [`Source`]); to another format, the mesh is written with the source's UVs and vertex colours
/// where the format holds them (glTF, OBJ: one value per welded vertex); when `mesh` no longer
/// has the source's connectivity (a level of the hierarchy, a subdivided copy), it is written
/// bare. Either way the report names what the output does not keep. The write is atomic, as with
/// [`save`].
pub fn save_with_source(
    path: impl AsRef<Path>,
    mesh: &TriMesh,
    source: &Source,
) -> Result<SaveReport, IoError> {
    let path = path.as_ref();
    let format = format_of(path)?;
    check_writable(mesh, path)?;
    let mut report = SaveReport::default();
    let name = source.path.display();
    if let (SourceData::Stl(stl), Format::Stl) = (&source.data, format) {
        // STL keeps nothing per vertex: its header is written back whatever the connectivity.
        atomic::write(path, |w| stl::write_with_header(w, mesh, &stl.header))?;
        if !stl.unkept.is_empty() {
            report
                .warnings
                .push(format!("not kept from {name}: {}", stl.unkept.join("; ")));
        }
        return Ok(report);
    }
    if source.writes_back_as(format) && source.matches(mesh) {
        match &source.data {
            SourceData::Obj(bytes) => {
                let mut shared = 0;
                atomic::write(path, |w| {
                    shared = obj::write_back(w, bytes, source, mesh)?;
                    Ok(())
                })?;
                report.texture_coordinates_follow = true;
                if shared > 0 {
                    report.warnings.push(format!(
                        "{shared} texture coordinates of {name} are each shared by several \
                         vertices that moved, so they stay where they were (the texture slides \
                         with those vertices)"
                    ));
                }
            }
            SourceData::Ply(bytes) => {
                atomic::write(path, |w| {
                    report.texture_coordinates_follow = ply::write_back(w, bytes, source, mesh)?;
                    Ok(())
                })?;
            }
            SourceData::Gltf(gltf) => {
                gltf::write_back(path, format, gltf, source, mesh, &mut report)?
            }
            SourceData::Plain | SourceData::Unkept(_) | SourceData::Stl(_) => {
                save_as(path, mesh, format)?
            }
        }
        return Ok(report);
    }
    let name = name.to_string();
    let carries = !source.writes_back_as(format) && source.matches(mesh);
    // A glTF scene or an OBJ into OBJ or glTF: its parts, materials, UVs, normals and colours.
    if carries && matches!(format, Format::Obj | Format::Glb | Format::Gltf) {
        if let Some(mut scene) = source.scene(mesh) {
            let mut merged_colours = 0;
            match format {
                Format::Obj => obj::write_scene(path, &scene, mesh, &mut merged_colours)?,
                _ => gltf::write_scene(path, format == Format::Glb, &mut scene, mesh)?,
            }
            let mut lost = source.contents_beyond_scene(&scene, format);
            if merged_colours > 0 {
                lost.push(format!(
                    "the colour borders at {merged_colours} vertices (an OBJ vertex keeps one colour; the first was kept)"
                ));
            }
            lost.append(&mut scene.warnings);
            if !lost.is_empty() {
                report.warnings.push(format!(
                    "{}; not kept from {name}: {}",
                    written_as(format, &scene.carried()),
                    lost.join("; ")
                ));
            }
            return Ok(report);
        }
    }
    // Otherwise what the format can hold per vertex (UVs, colours; normals into PLY) is carried
    // when the mesh still has the source's vertices; the rest is named.
    let extra = if carries
        && matches!(
            format,
            Format::Obj | Format::Glb | Format::Gltf | Format::Ply
        ) {
        source.vertex_attributes()
    } else {
        carry::VertexAttributes::default()
    };
    let (mut kept, mut lost) = extra.describe();
    let mut beyond = source.contents_beyond(&extra);
    match format {
        Format::Obj => atomic::write(path, |w| obj::write_with(w, mesh, &extra))?,
        Format::Glb => atomic::write(path, |w| gltf::write_glb_with(w, mesh, &extra))?,
        Format::Gltf => gltf::write_gltf_with(path, mesh, &extra)?,
        Format::Ply if carries => {
            // Normals, when the file had them, are recomputed from the faired shape: one per
            // vertex, so the split ones (hard edges) become smooth; how many is said.
            let had_normals = beyond
                .iter()
                .any(|item| item == "normals" || item.starts_with("normals ("));
            let normals = had_normals.then(|| gltf::unit_vertex_normals(mesh));
            atomic::write(path, |w| {
                ply::write_with(w, mesh, &extra, normals.as_deref())
            })?;
            if had_normals {
                kept.push("normals (recomputed)");
                beyond.retain(|item| item != "normals" && !item.starts_with("normals ("));
                let split = source.split_normal_vertices(mesh);
                if split > 0 {
                    lost.push(format!(
                        "the split normals (hard edges, seams) at {split} vertices: a PLY vertex holds one normal, recomputed smooth from the faired shape"
                    ));
                }
            }
        }
        _ => save_as(path, mesh, format)?,
    }
    lost.extend(beyond);
    if !lost.is_empty() {
        let why = if source.writes_back_as(format) {
            "the mesh no longer has its connectivity (a level of the hierarchy or a changed copy), so it is written as a bare mesh".to_string()
        } else {
            written_as(format, &kept)
        };
        report
            .warnings
            .push(format!("{why}; not kept from {name}: {}", lost.join("; ")));
    }
    Ok(report)
}

/// Where a mesh derived from a loaded one by removing vertices (a coarse level of the
/// hierarchy) came from, for [`save_derived_with_source`].
#[derive(Clone, Copy, Debug)]
pub struct Derivation<'a> {
    /// The mesh it was derived from, with the loaded connectivity (its positions do not matter).
    pub base: &'a TriMesh,
    /// Per vertex of the derived mesh: the vertex of `base` it is.
    pub vertex_origin: &'a [u32],
    /// Per triangle of the derived mesh: the triangle of `base` it is what is left of.
    pub face_origin: &'a [u32],
}

/// Save a mesh derived from the loaded one by removing vertices (a coarse level of the
/// hierarchy), keeping what can be kept per surviving vertex: into OBJ or glTF, from a glTF or
/// OBJ source, its part names, materials (and textures), and the UVs and colours of the kept
/// vertices (a corner moved onto another vertex takes that vertex's UV in the same material);
/// into OBJ, glTF or PLY from any source, the UVs and colours of the kept vertices. Normals are
/// recomputed, smooth, from the coarse shape. The report names what is not kept (split normals,
/// morph targets, the node tree's transforms, ...). A derivation that does not fit `mesh` or
/// `source` is written as [`save_with_source`] writes it (bare, with the report saying so).
pub fn save_derived_with_source(
    path: impl AsRef<Path>,
    mesh: &TriMesh,
    derivation: &Derivation<'_>,
    source: &Source,
) -> Result<SaveReport, IoError> {
    let path = path.as_ref();
    let format = format_of(path)?;
    let fits = derivation.vertex_origin.len() == mesh.positions.len()
        && derivation.face_origin.len() == mesh.triangles.len()
        && source.matches(derivation.base)
        && derivation
            .vertex_origin
            .iter()
            .all(|&v| (v as usize) < derivation.base.positions.len());
    if !fits || (source.matches(mesh) && mesh.positions.len() == derivation.base.positions.len()) {
        return save_with_source(path, mesh, source);
    }
    check_writable(mesh, path)?;
    let mut report = SaveReport::default();
    let name = source.path.display().to_string();
    let why = "a coarser level has fewer vertices";
    let mut lost: Vec<String> = Vec::new();
    let kept: Vec<&str>;
    let scene = matches!(format, Format::Obj | Format::Glb | Format::Gltf)
        .then(|| source.scene(derivation.base))
        .flatten();
    if let Some(scene) = scene {
        let (mut derived, unplaced) = scene.derive(
            derivation.base,
            mesh,
            derivation.vertex_origin,
            derivation.face_origin,
        );
        let mut merged_colours = 0;
        match format {
            Format::Obj => obj::write_scene(path, &derived, mesh, &mut merged_colours)?,
            _ => gltf::write_scene(path, format == Format::Glb, &mut derived, mesh)?,
        }
        kept = derived.carried();
        if unplaced > 0 {
            lost.push(format!(
                "the part and material of {unplaced} triangles (their source triangle was not found)"
            ));
        }
        if merged_colours > 0 {
            lost.push(format!(
                "the colour borders at {merged_colours} vertices (an OBJ vertex keeps one colour; the first was kept)"
            ));
        }
        if scene.normals {
            lost.push("the file's own normals and their split (hard edges): they are recomputed, smooth, from the coarse shape".into());
        }
        let mut contents = source.contents_beyond_scene(&scene, format);
        if format != Format::Obj {
            for item in &mut contents {
                if item.starts_with("the node tree") {
                    *item = format!("{item}: its hierarchy and transforms (each part becomes one node, names kept, transforms baked into the positions)");
                }
            }
        }
        lost.extend(contents);
        lost.extend(scene.warnings);
    } else {
        let full = source.vertex_attributes();
        let pick = |values: &[[f32; 2]]| -> Vec<[f32; 2]> {
            derivation
                .vertex_origin
                .iter()
                .map(|&v| values[v as usize])
                .collect()
        };
        let extra = carry::VertexAttributes {
            uvs: full.uvs.as_deref().map(pick),
            colours: full.colours.as_ref().map(|values| {
                derivation
                    .vertex_origin
                    .iter()
                    .map(|&v| values[v as usize])
                    .collect()
            }),
            uv_splits_merged: full.uv_splits_merged,
            colour_splits_merged: full.colour_splits_merged,
        };
        let (carried, mut merged) = extra.describe();
        match format {
            Format::Obj => atomic::write(path, |w| obj::write_with(w, mesh, &extra))?,
            Format::Glb => atomic::write(path, |w| gltf::write_glb_with(w, mesh, &extra))?,
            Format::Gltf => gltf::write_gltf_with(path, mesh, &extra)?,
            Format::Ply => atomic::write(path, |w| ply::write_with(w, mesh, &extra, None))?,
            _ => save_as(path, mesh, format)?,
        }
        let holds = matches!(
            format,
            Format::Obj | Format::Glb | Format::Gltf | Format::Ply
        );
        kept = if holds { carried } else { Vec::new() };
        if holds {
            lost.append(&mut merged);
            lost.extend(source.contents_beyond(&extra));
        } else {
            lost.extend(source.contents());
        }
    }
    if !lost.is_empty() {
        let how = if kept.is_empty() {
            format!("it is written as a bare {format} mesh")
        } else {
            format!(
                "it is written as {format} with the {} of the kept vertices",
                and_list(&kept)
            )
        };
        report.warnings.push(format!(
            "{why}: {how}; not kept from {name}: {}",
            lost.join("; ")
        ));
    }
    Ok(report)
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

/// How a warning says what a written file holds besides the bare mesh.
fn written_as(format: Format, kept: &[&str]) -> String {
    if kept.is_empty() {
        format!("it is written as a bare {format} mesh")
    } else {
        format!("it is written as {format} with its {}", and_list(kept))
    }
}

/// "a", "a and b", "a, b and c".
fn and_list(items: &[&str]) -> String {
    match items {
        [] => String::new(),
        [one] => one.to_string(),
        [rest @ .., last] => format!("{} and {last}", rest.join(", ")),
    }
}

/// Refuse meshes that no reader could load back: no triangles, NaN/inf, indices out of range.
fn check_writable(mesh: &TriMesh, path: &Path) -> Result<(), IoError> {
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

/// Where a `.gltf` file's buffer goes: `<stem>.bin` beside it.
/// The folder an output file goes into (`.` for a bare file name) and its name without the
/// extension (`mesh` when it has none): where files written beside it go, and their prefix.
pub(crate) fn folder_and_stem(output: &Path) -> (PathBuf, String) {
    let folder = match output.parent() {
        Some(dir) if !dir.as_os_str().is_empty() => dir.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let stem = output
        .file_stem()
        .map_or_else(|| "mesh".into(), |s| s.to_string_lossy().into_owned());
    (folder, stem)
}

pub fn gltf_bin_path(gltf_path: &Path) -> PathBuf {
    gltf_path.with_extension("bin")
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
        let err = load(Path::new("/nowhere/mesh.xyz")).unwrap_err();
        assert!(err.to_string().starts_with("/nowhere/mesh.xyz: "), "{err}");
        assert!(err.to_string().contains("xyz"), "{err}");
    }

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

    #[test]
    fn finish_warns_about_non_manifold_edges() {
        let mesh = crate::mesh::fixtures::three_triangles_on_one_edge();
        let loaded = finish(mesh, &LoadOptions::default());
        assert!(
            loaded
                .report
                .warnings
                .iter()
                .any(|w| w.contains("non-manifold edges")),
            "{:?}",
            loaded.report.warnings
        );
    }
}
