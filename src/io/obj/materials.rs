//! An OBJ's materials, read from its `mtllib` files beside it: name, base colour, metallic,
//! roughness and base colour texture.

use super::line::rest_of;
use crate::io::origin::Origin;
use crate::io::scene::{image_file_name, image_mime_type, Image, ImageData, Material};
use crate::io::text::tokens;
use std::path::{Path, PathBuf};

/// The materials `names` as the `.mtl` files `libraries` (beside the OBJ) define them: Kd and d
/// (or Tr) as the base colour, Pm and Pr, and map_Kd (resolved beside the `.mtl`). A material
/// or file that cannot be found is named in `warnings` and gets a white base colour.
pub(super) fn read_materials(
    names: &[String],
    libraries: &[String],
    origin: &Origin,
    warnings: &mut Vec<String>,
) -> Vec<Material> {
    let mut materials: Vec<Material> = names
        .iter()
        .map(|name| Material {
            name: name.clone(),
            base_colour: [1.0; 4],
            metallic: 0.0,
            roughness: 1.0,
            texture: None,
            sampler: Default::default(),
            tex_coord: 0,
            texture_transform: None,
        })
        .collect();
    if names.is_empty() {
        return materials;
    }
    let mut found = vec![false; names.len()];
    let mut unkept: Vec<String> = Vec::new();
    // The libraries that could not be read, each with why.
    let mut unread: Vec<String> = Vec::new();
    for library in libraries {
        let (text, file) = match read_library(library, origin) {
            Ok(read) => read,
            Err(why) => {
                unread.push(format!("{library} ({why})"));
                continue;
            }
        };
        let mut read = MtlRead {
            names,
            materials: &mut materials,
            found: &mut found,
            unkept: &mut unkept,
            warnings,
        };
        read.lines(&text, &file);
    }
    warn_about_missing(names, &found, libraries, &unread, warnings);
    if !unkept.is_empty() {
        warnings.push(format!(
            "material maps other than the diffuse map ({})",
            unkept.join(", ")
        ));
    }
    materials
}

/// The `.mtl` file `library` beside the OBJ, and its path; or why it cannot be read.
fn read_library(library: &str, origin: &Origin) -> Result<(Vec<u8>, PathBuf), String> {
    let Some(base) = &origin.base_dir else {
        return Err("the input was read from memory, so it cannot be found".into());
    };
    let file = base.join(library);
    match crate::io::files::read(&file) {
        Ok(text) => Ok((text, file)),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            let obj = origin.path.file_name().unwrap_or_default();
            Err(format!("not found beside {}", Path::new(obj).display()))
        }
        Err(e) => Err(format!("{} cannot be read: {e}", file.display())),
    }
}

/// Reading one `.mtl` file into the materials `names`: which were found, the maps not kept,
/// and the warnings.
struct MtlRead<'a> {
    names: &'a [String],
    materials: &'a mut [Material],
    found: &'a mut [bool],
    unkept: &'a mut Vec<String>,
    warnings: &'a mut Vec<String>,
}

impl MtlRead<'_> {
    /// The lines of the `.mtl` `text` at `file`: a parser's loop over the keywords, which reads
    /// best in one piece.
    fn lines(&mut self, text: &[u8], file: &Path) {
        let folder = file.parent().map(Path::to_path_buf).unwrap_or_default();
        let names = self.names;
        let mut current: Option<usize> = None;
        for line in text.split(|&b| b == b'\n') {
            let mut words = tokens(line);
            let Some(keyword) = words.next() else {
                continue;
            };
            if keyword == b"newmtl" {
                current = rest_of(words).and_then(|name| names.iter().position(|n| *n == name));
                if let Some(m) = current {
                    self.found[m] = true;
                }
                continue;
            }
            let Some(m) = current else { continue };
            let material = &mut self.materials[m];
            let words: Vec<&[u8]> = words.collect();
            let numbers: Vec<f32> = words
                .iter()
                .map_while(|w| crate::io::text::parse_f32(w))
                .filter(|v| v.is_finite())
                .collect();
            match keyword {
                b"Kd" if numbers.len() >= 3 => {
                    material.base_colour[..3].copy_from_slice(&numbers[..3]);
                }
                b"d" if !numbers.is_empty() => material.base_colour[3] = numbers[0],
                b"Tr" if !numbers.is_empty() => material.base_colour[3] = 1.0 - numbers[0],
                b"Pm" if !numbers.is_empty() => material.metallic = numbers[0],
                b"Pr" if !numbers.is_empty() => material.roughness = numbers[0],
                b"map_Kd" => {
                    // Options (-s 1 1 1, -clamp on, ...) come first; the file name is last.
                    let Some(name) = words
                        .last()
                        .map(|w| String::from_utf8_lossy(w).into_owned())
                    else {
                        continue;
                    };
                    let image = folder.join(name.replace('\\', "/"));
                    if crate::io::files::is_file(&image) {
                        material.texture = Some(Image {
                            name: image_file_name(
                                &image.file_name().map_or_else(
                                    || name.clone(),
                                    |n| n.to_string_lossy().into_owned(),
                                ),
                                image_mime_type(&[], &image),
                            ),
                            data: ImageData::File(image),
                        });
                    } else {
                        self.warnings.push(format!(
                            "the texture {name} of material '{}' (not found beside {})",
                            material.name,
                            file.display()
                        ));
                    }
                }
                b"Ka" | b"Ks" | b"Ke" | b"Ns" | b"Ni" | b"illum" | b"Tf" => {}
                other if other.starts_with(b"map_") || other == b"bump" || other == b"norm" => {
                    let what = format!("'{}' {}", material.name, String::from_utf8_lossy(other));
                    if !self.unkept.contains(&what) {
                        self.unkept.push(what);
                    }
                }
                _ => {}
            }
        }
    }
}

/// Warnings for the libraries that could not be read (once, with why, when none could) and the
/// materials no library defines.
fn warn_about_missing(
    names: &[String],
    found: &[bool],
    libraries: &[String],
    unread: &[String],
    warnings: &mut Vec<String>,
) {
    let missing: Vec<&str> = names
        .iter()
        .zip(found)
        .filter(|(_, found)| !**found)
        .map(|(name, _)| name.as_str())
        .collect();
    let quoted: Vec<String> = missing.iter().map(|name| format!("'{name}'")).collect();
    let quoted: Vec<&str> = quoted.iter().map(String::as_str).collect();
    if unread.len() == libraries.len() && !unread.is_empty() {
        // Nothing defines the materials: said once, with why.
        warnings.push(format!(
            "the material {} {}, so the materials {} are written white, without their colours and textures",
            if unread.len() == 1 { "library" } else { "libraries" },
            unread.join(" and "),
            crate::io::text::and_list(&quoted)
        ));
    } else {
        for library in unread {
            warnings.push(format!("the material library {library}"));
        }
        if !missing.is_empty() && !libraries.is_empty() {
            warnings.push(format!(
                "the definition of material(s) {} (not in {}): written white",
                missing.join(", "),
                libraries.join(", ")
            ));
        }
    }
}
