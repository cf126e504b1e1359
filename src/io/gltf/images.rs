//! The external image files of a written-back document: embedded in a GLB, copied beside a
//! `.gltf` written to another folder.

use super::buffers::set_buffer_length;
use super::uri::{percent_decode, percent_encode};
use crate::io::origin::Origin;
use crate::io::scene::image_mime_type;
use crate::io::SaveReport;
use serde_json::{json, Value};
use std::path::{Path, PathBuf};

/// The external image files of the document (`uri` that is not a data: URI), resolved against
/// the input's folder; those that cannot be found are named in the report and left as they are.
pub(super) fn external_images(
    json: &Value,
    origin: &Origin,
    report: &mut SaveReport,
) -> Vec<(usize, PathBuf)> {
    let mut found = Vec::new();
    let images = json.get("images").and_then(Value::as_array);
    for (i, image) in images.into_iter().flatten().enumerate() {
        let Some(uri) = image.get("uri").and_then(Value::as_str) else {
            continue;
        };
        if uri.starts_with("data:") {
            continue;
        }
        let Some(base) = &origin.base_dir else {
            report.warnings.push(format!(
                "image {i} refers to the file {uri:?}, which cannot be found (the input was read from memory): the reference is kept as it was"
            ));
            continue;
        };
        let file = percent_decode(uri).map(|relative| base.join(relative));
        match file {
            Some(file) if crate::io::files::is_file(&file) => found.push((i, file)),
            _ => report.warnings.push(format!(
                "image {i} refers to {uri:?}, which is not beside the input: the reference is kept as it was"
            )),
        }
    }
    found
}

/// A GLB is self-contained: external images are copied into its binary chunk, each in a buffer
/// view of its own.
pub(super) fn embed_images(
    json: &mut Value,
    bin: &mut Vec<u8>,
    images: Vec<(usize, PathBuf)>,
    report: &mut SaveReport,
) {
    for (i, file) in images {
        let bytes = match crate::io::files::read(&file) {
            Ok(bytes) => bytes,
            Err(e) => {
                report.warnings.push(format!(
                    "image {i} ({}) cannot be read ({e}): the reference is kept as it was",
                    file.display()
                ));
                continue;
            }
        };
        while !bin.len().is_multiple_of(4) {
            bin.push(0);
        }
        let view = json!({"buffer": 0, "byteOffset": bin.len(), "byteLength": bytes.len()});
        bin.extend_from_slice(&bytes);
        let Some(root) = json.as_object_mut() else {
            return;
        };
        let views = root
            .entry("bufferViews")
            .or_insert_with(|| json!([]))
            .as_array_mut();
        let Some(views) = views else { return };
        views.push(view);
        let view_index = views.len() - 1;
        if let Some(image) = root.get_mut("images").and_then(|list| list.get_mut(i)) {
            if let Some(image) = image.as_object_mut() {
                image.remove("uri");
                image.insert("bufferView".into(), json!(view_index));
                if !image.contains_key("mimeType") {
                    image.insert("mimeType".into(), json!(image_mime_type(&bytes, &file)));
                }
            }
        }
    }
    set_buffer_length(json, bin.len());
}

/// A `.gltf` keeps its images as files beside it: those not already in the output's folder are
/// copied there (as `<output stem>_<name>` when another file of that name is there) and the
/// copies to make are returned; those in the same folder are referenced as they were.
pub(super) fn place_image_files(
    json: &mut Value,
    images: Vec<(usize, PathBuf)>,
    output: &Path,
) -> Vec<(PathBuf, PathBuf)> {
    let (out_dir, stem) = crate::io::folder_and_stem(output);
    let same = crate::io::files::same_file;
    let mut copies: Vec<(PathBuf, PathBuf)> = Vec::new();
    for (i, file) in images {
        if file.parent().is_some_and(|dir| same(dir, &out_dir)) {
            continue;
        }
        let name = file.file_name().map_or_else(
            || format!("image{i}.png"),
            |n| n.to_string_lossy().into_owned(),
        );
        let mut target = out_dir.join(&name);
        let taken = |target: &Path| {
            copies
                .iter()
                .any(|(from, to)| to == target && *from != file)
                || (crate::io::files::exists(target)
                    && crate::io::files::read(target).ok() != crate::io::files::read(&file).ok())
        };
        if taken(&target) {
            target = out_dir.join(format!("{stem}_{name}"));
        }
        let uri_name = target
            .file_name()
            .map_or_else(|| name.clone(), |n| n.to_string_lossy().into_owned());
        if let Some(image) = json.get_mut("images").and_then(|list| list.get_mut(i)) {
            image["uri"] = json!(percent_encode(&uri_name));
        }
        if !copies.iter().any(|(_, to)| *to == target) {
            copies.push((file, target));
        }
    }
    copies
}
