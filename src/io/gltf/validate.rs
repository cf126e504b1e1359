//! What is checked and refused before a glTF document is read: the GLB header, glTF 1.0 files,
//! required extensions fairmesh cannot read and what the `gltf` crate's validation finds, each
//! with the place in the file and, where there is one, what to do.

use crate::io::IoError;
use gltf_json as json;
use std::path::Path;

/// The JSON of a `.gltf` (the whole file) or of a GLB (its first chunk).
pub(super) fn json_text(bytes: &[u8]) -> Option<&[u8]> {
    if !bytes.starts_with(b"glTF") {
        return Some(bytes);
    }
    let length = u32::from_le_bytes(bytes.get(12..16)?.try_into().ok()?) as usize;
    bytes.get(20..20usize.checked_add(length)?)
}

/// The GLB header's length, checked before the `gltf` crate sees it: gltf 1.4 subtracts the
/// header size from it unchecked (an overflow panic in debug builds, found by fuzzing).
pub(super) fn check_glb_header(bytes: &[u8], path: &Path) -> Result<(), IoError> {
    if !bytes.starts_with(b"glTF") {
        return Ok(());
    }
    let Some(declared) = bytes
        .get(8..12)
        .and_then(|b| b.try_into().ok())
        .map(u32::from_le_bytes)
    else {
        return Err(IoError::at_byte(
            path,
            0,
            format!(
                "GLB container: the file is truncated: the 12-byte header is cut off at {} bytes",
                bytes.len()
            ),
        ));
    };
    // Version 1 is glTF 1.0's container (KHR_binary_glTF), with another chunk layout.
    let version = u32::from_le_bytes(bytes[4..8].try_into().expect("4 bytes"));
    if version != 2 {
        return Err(IoError::at_byte(
            path,
            4,
            format!(
                "GLB container version {version}{}: fairmesh reads glTF 2.0 (GLB version 2); save \
                 the file again as glTF 2.0",
                if version == 1 { " (glTF 1.0)" } else { "" }
            ),
        ));
    }
    if declared < 12 {
        return Err(IoError::at_byte(
            path,
            8,
            format!("GLB container: the header declares a total length of {declared} bytes, less than the header itself"),
        ));
    }
    if declared as usize > bytes.len() {
        return Err(IoError::at_byte(
            path,
            8,
            format!(
                "GLB container: the file is truncated: the header declares {declared} bytes but the file has {}",
                bytes.len()
            ),
        ));
    }
    Ok(())
}

/// When glTF 2.0's JSON does not fit a file, whether it is a glTF 1.0 file (whose JSON holds
/// objects keyed by name where 2.0 has arrays): the error says so rather than where the first
/// array was not one.
pub(super) fn older_gltf(bytes: &[u8], path: &Path) -> Option<IoError> {
    let json: serde_json::Value = serde_json::from_slice(json_text(bytes)?).ok()?;
    let version = json.get("asset")?.get("version")?.as_str()?;
    version.starts_with("1.").then(|| {
        IoError::at_element(
            path,
            "asset.version",
            format!(
                "glTF {version}: fairmesh reads glTF 2.0 (1.0 files are laid out differently); \
                 save the file again as glTF 2.0"
            ),
        )
    })
}

/// Required extensions fairmesh reads itself (the `gltf` crate, as built here, refuses them):
/// KHR_mesh_quantization only lets attributes be stored as integers, which the accessor reading
/// decodes (and the write-back encodes again); KHR_texture_transform places a texture on its
/// texture coordinates (the editor draws it so, outputs keep it); the others give a texture an
/// image in another format (KTX2, WebP, AVIF, DDS), and fairmesh never decodes those: it
/// carries their bytes.
fn read_here(extension: &str) -> bool {
    matches!(extension, "KHR_mesh_quantization" | "KHR_texture_transform")
        || IMAGE_FORMATS.contains(&extension)
}

/// Texture extensions whose `source` names a texture's image in their format (the texture's own
/// `source`, when it has one, is a PNG or JPEG fallback).
pub(crate) const IMAGE_FORMATS: [&str; 4] = [
    "KHR_texture_basisu",
    "EXT_texture_webp",
    "EXT_texture_avif",
    "MSFT_texture_dds",
];

/// A validation path `array[i]rest` (`textures[3].source`, `extensionsRequired[0] = "name"`) as
/// its top-level array, the index and the rest.
fn element(at: &str) -> Option<(&str, usize, &str)> {
    let (array, rest) = at.split_once('[')?;
    let (index, rest) = rest.split_once(']')?;
    Some((array, index.parse().ok()?, rest))
}

/// What a required extension that fairmesh cannot read holds, and what to do, for the error
/// that names it.
fn extension_content(name: &str) -> (&'static str, &'static str) {
    match name {
        "KHR_draco_mesh_compression" => (
            " (Draco-compressed geometry)",
            ": save the file again without mesh compression",
        ),
        "EXT_meshopt_compression" => (
            " (meshoptimizer-compressed buffers)",
            ": save the file again without compression",
        ),
        "KHR_technique_webgl" | "KHR_materials_common" => (" (glTF 1.0 materials)", ""),
        _ => ("", ""),
    }
}

/// What `gltf::Gltf::from_slice` validates, after a check that its validation needs: gltf-json
/// 1.4 looks up every primitive's POSITION accessor by index without a bounds check (a panic,
/// found by fuzzing). A required extension fairmesh cannot read is named first: its data (a
/// Draco-compressed mesh's accessors have no buffer views) fails the other checks too, which
/// would otherwise be the error.
pub(super) fn validate(
    root: &json::Root,
    plain: &serde_json::Value,
    path: &Path,
) -> Result<(), IoError> {
    use json::validation::{Checked, Validate};
    let mut unsupported = (root.extensions_required.iter().enumerate()).filter(|(_, name)| {
        !read_here(name) && !json::extensions::ENABLED_EXTENSIONS.contains(&name.as_str())
    });
    if let Some((i, name)) = unsupported.next() {
        let others = match unsupported.count() {
            0 => String::new(),
            n => format!(" ({n} more required extensions fairmesh cannot read)"),
        };
        let (content, advice) = extension_content(name);
        return Err(IoError::at_element(
            path,
            format!("extensionsRequired[{i}]"),
            format!(
                "the file needs the extension {name}{content}, which fairmesh does not \
                 support{others}{advice}"
            ),
        ));
    }
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            let position = primitive
                .attributes
                .get(&Checked::Valid(json::mesh::Semantic::Positions));
            if let Some(index) = position.filter(|i| i.value() >= root.accessors.len()) {
                return Err(IoError::at_element(
                    path,
                    format!("meshes[{m}].primitives[{p}].attributes.POSITION"),
                    format!(
                        "invalid glTF: accessor {} does not exist (the file has {})",
                        index.value(),
                        root.accessors.len()
                    ),
                ));
            }
        }
    }
    let mut errors = Vec::new();
    root.validate(root, json::Path::new, &mut |where_, what| {
        let at = where_();
        // The `gltf` crate calls every required extension it does not handle unsupported,
        // including those read here.
        let handled = match (what, element(at.as_str())) {
            (json::validation::Error::Unsupported, Some(("extensionsRequired", i, _))) => {
                (root.extensions_required.get(i)).is_some_and(|name| read_here(name))
            }
            // A texture whose only image is in another format has it in its extension.
            (json::validation::Error::Missing, Some(("textures", t, ".source"))) => {
                (plain["textures"][t]["extensions"].as_object()).is_some_and(|extensions| {
                    (extensions.keys()).any(|name| IMAGE_FORMATS.contains(&name.as_str()))
                })
            }
            _ => false,
        };
        if !handled {
            errors.push((at, what))
        }
    });
    if errors.is_empty() {
        Ok(())
    } else {
        Err(describe(::gltf::Error::Validation(errors), path))
    }
}

pub(super) fn describe(error: ::gltf::Error, path: &Path) -> IoError {
    match error {
        ::gltf::Error::Deserialize(e) if e.line() > 0 => IoError::at_line(
            path,
            e.line(),
            format!("invalid glTF JSON (column {}): {e}", e.column()),
        ),
        ::gltf::Error::Deserialize(e) => IoError::invalid(path, format!("invalid glTF JSON: {e}")),
        ::gltf::Error::Binary(e) => {
            IoError::at_element(path, "GLB container", format!("invalid GLB: {e}"))
        }
        ::gltf::Error::Validation(errors) => {
            let count = errors.len();
            match errors.into_iter().next() {
                Some((where_, what)) => IoError::at_element(
                    path,
                    where_.to_string(),
                    format!("invalid glTF: {what} ({count} problems in all)"),
                ),
                None => IoError::invalid(path, "invalid glTF"),
            }
        }
        other => IoError::invalid(path, format!("invalid glTF: {other}")),
    }
}
