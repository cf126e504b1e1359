//! The files an OBJ names beside it, for an OBJ written back into another folder: its material
//! libraries (`mtllib`) and the images those name (`map_Kd`, the other `map_` maps, `bump`,
//! `norm`, `disp`, `decal`, `refl`). The written-back file keeps its `mtllib` lines as they
//! were, so its libraries and their images are copied beside it under the same relative names;
//! without them a viewer shows the mesh without its materials.
//!
//! A file already there with the same bytes is left as it is. What cannot be copied is named in
//! a warning and the reference is kept as written: a file that is not beside the input, a name
//! that leads out of the folder (`../`), a different file of that name already beside the output
//! (it is never overwritten), or an input read from memory.

use super::line::rest_of;
use crate::io::atomic::{self, Staged};
use crate::io::origin::Origin;
use crate::io::text::tokens;
use crate::io::IoError;
use std::path::{Component, Path, PathBuf};

/// The copies (from, to) that put the material libraries the OBJ `bytes` names, and their
/// images, beside `output`; none when the output is in the input's folder. What cannot be
/// copied is named in `warnings`.
pub(crate) fn companion_copies(
    bytes: &[u8],
    origin: &Origin,
    output: &Path,
    warnings: &mut Vec<String>,
) -> Vec<(PathBuf, PathBuf)> {
    let (out_dir, _) = crate::io::folder_and_stem(output);
    if let Some(base) = &origin.base_dir {
        if same_folder(base, &out_dir) {
            return Vec::new();
        }
    }
    let libraries = libraries_named(bytes);
    if libraries.is_empty() {
        return Vec::new();
    }
    let Some(base) = &origin.base_dir else {
        warnings.push(format!(
            "the material libraries {} are not copied beside {}: the input was read from memory, so they cannot be found",
            libraries.join(", "),
            output.display()
        ));
        return Vec::new();
    };
    let mut copies = Copies {
        out_dir: &out_dir,
        output,
        input: &origin.path,
        planned: Vec::new(),
        warnings,
    };
    for library in &libraries {
        let Some(file) = copies.plan(base, library, "material library") else {
            continue;
        };
        let Ok(text) = crate::io::files::read(&file) else {
            continue;
        };
        let library_dir = Path::new(library).parent().unwrap_or(Path::new(""));
        for image in images_named(&text) {
            let relative = library_dir.join(&image);
            copies.plan(base, &relative.to_string_lossy(), "image");
        }
    }
    copies.planned
}

/// The copies staged (see [`atomic::stage`]), with the sub-folders of the output's folder that
/// nested names need made first (the output's folder itself must exist, as for the OBJ).
pub(crate) fn stage_copies(
    copies: &[(PathBuf, PathBuf)],
    output: &Path,
) -> Result<Vec<Staged>, IoError> {
    let (out_dir, _) = crate::io::folder_and_stem(output);
    copies
        .iter()
        .map(|(from, to)| {
            let in_memory = crate::io::files::in_memory(to);
            if let Some(folder) = to
                .parent()
                .filter(|f| !in_memory && *f != out_dir && out_dir.is_dir())
            {
                std::fs::create_dir_all(folder).map_err(|source| IoError::Write {
                    path: to.clone(),
                    source,
                })?;
            }
            atomic::stage_copy(from, to)
        })
        .collect()
}

/// The `mtllib` names of an OBJ, in file order, each once.
fn libraries_named(bytes: &[u8]) -> Vec<String> {
    let mut names: Vec<String> = Vec::new();
    for line in bytes.split(|&b| b == b'\n') {
        // Only `mtllib` lines are split into words: the `v` and `f` lines are most of the file.
        if !line.trim_ascii_start().starts_with(b"mtllib") {
            continue;
        }
        let mut words = tokens(line);
        if words.next() == Some(b"mtllib") {
            if let Some(name) = rest_of(words) {
                if !names.contains(&name) {
                    names.push(name);
                }
            }
        }
    }
    names
}

/// The image files a `.mtl` names (the last word of a map line: options come first), in file
/// order, each once, with `\` read as `/`.
fn images_named(text: &[u8]) -> Vec<String> {
    let mut names: Vec<String> = Vec::new();
    for line in text.split(|&b| b == b'\n') {
        let mut words = tokens(line);
        let Some(keyword) = words.next() else {
            continue;
        };
        let is_map = keyword.starts_with(b"map_")
            || matches!(keyword, b"bump" | b"norm" | b"disp" | b"decal" | b"refl");
        if !is_map {
            continue;
        }
        if let Some(name) = words.last() {
            let name = String::from_utf8_lossy(name).replace('\\', "/");
            if !names.contains(&name) {
                names.push(name);
            }
        }
    }
    names
}

/// Whether two folders are one (both resolved; a folder that cannot be resolved is another).
fn same_folder(a: &Path, b: &Path) -> bool {
    crate::io::files::same_file(a, b)
}

/// The copies planned so far and the warnings for those that cannot be made.
struct Copies<'a> {
    out_dir: &'a Path,
    output: &'a Path,
    input: &'a Path,
    planned: Vec<(PathBuf, PathBuf)>,
    warnings: &'a mut Vec<String>,
}

impl Copies<'_> {
    /// Plans the copy of `name` (relative to the input's folder `base`) to the same name beside
    /// the output; returns the file beside the input when it exists.
    fn plan(&mut self, base: &Path, name: &str, what: &str) -> Option<PathBuf> {
        let relative = Path::new(name);
        if relative.is_absolute() {
            // An absolute name resolves from anywhere.
            return None;
        }
        let file = base.join(relative);
        if !crate::io::files::is_file(&file) {
            self.warn(what, name, "it is not beside the input");
            return None;
        }
        if relative
            .components()
            .any(|c| !matches!(c, Component::Normal(_)))
        {
            self.warn(what, name, "its name leads out of the input's folder");
            return Some(file);
        }
        let target = self.out_dir.join(relative);
        if self.planned.iter().any(|(_, to)| *to == target) {
            return Some(file);
        }
        if crate::io::files::exists(&target) {
            if crate::io::files::read(&target).ok() != crate::io::files::read(&file).ok() {
                self.warn(
                    what,
                    name,
                    "a different file of that name is already there (the output refers to it)",
                );
            }
            return Some(file);
        }
        self.planned.push((file.clone(), target));
        Some(file)
    }

    fn warn(&mut self, what: &str, name: &str, why: &str) {
        self.warnings.push(format!(
            "the {what} {name} named by {} is not copied beside {}: {why}",
            self.input.display(),
            self.output.display()
        ));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn libraries_and_their_images_are_read_with_options_and_backslashes() {
        let obj = b"# a cube\nmtllib a.mtl\nv 0 0 0\nmtllib b c.mtl\nmtllib a.mtl\n";
        assert_eq!(libraries_named(obj), ["a.mtl", "b c.mtl"]);
        let mtl =
            b"newmtl wood\nKd 1 1 1\nmap_Kd -s 1 1 1 tex\\wood.png\nbump -bm 0.5 wood_n.png\n\
                    map_Ks wood.png\nmap_Kd tex\\wood.png\nNs 10\n";
        assert_eq!(
            images_named(mtl),
            ["tex/wood.png", "wood_n.png", "wood.png"]
        );
    }
}
