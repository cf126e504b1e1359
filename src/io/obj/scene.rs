//! An OBJ file as a [`Scene`] (see [`crate::io::scene`]): its parts, file vertices, normals
//! turned with their faces, and materials ([`super::materials`]). Texture coordinates are turned
//! into the library's convention (`vt`'s v counts from the image's bottom row, the library's from
//! its top: see `io::uv_convention`).

use super::line::{resolve, rest_of, vertex_of};
use super::materials::read_materials;
use crate::io::origin::Origin;
use crate::io::scene::{Part, Primitive, Scene, SceneVertex};
use crate::io::text::tokens;
use crate::io::Format;
use crate::mesh::TriMesh;
use std::collections::HashMap;

/// The OBJ's parts (one per `o`/`g` pair), materials (from its `mtllib` files, read beside it),
/// and file vertices (one per distinct `v/vt/vn` corner), for saving in another format (see
/// [`crate::io::scene`]). Normals turn with their faces to `mesh`'s positions, slot by `vn` line as
/// in [`super::write_back`].
pub(crate) fn scene(bytes: &[u8], origin: &Origin, mesh: &TriMesh) -> Scene {
    let mut reader = SceneReader {
        origin,
        scene: Scene {
            groups_under_objects: true,
            ..Scene::default()
        },
        positions: Vec::with_capacity(origin.raw_vertices),
        colours: Vec::with_capacity(origin.raw_vertices),
        uvs: Vec::new(),
        normals: Vec::new(),
        libraries: Vec::new(),
        material_names: Vec::new(),
        corner_vertex: HashMap::new(),
        parts: HashMap::new(),
        object: None,
        group: None,
        material: None,
        current: None,
        corners: Vec::with_capacity(8),
    };
    for line in bytes.split(|&b| b == b'\n') {
        reader.line(line);
    }
    let mut scene = reader.scene;
    scene.materials = read_materials(
        &reader.material_names,
        &reader.libraries,
        origin,
        &mut scene.warnings,
    );
    scene.drop_degenerate();
    scene.turn_normals(mesh);
    scene
}

/// The scene being read from an OBJ's lines, with what the lines so far have given.
struct SceneReader<'a> {
    origin: &'a Origin,
    scene: Scene,
    positions: Vec<[f32; 3]>,
    colours: Vec<Option<[f32; 3]>>,
    uvs: Vec<[f32; 2]>,
    normals: Vec<[f32; 3]>,
    libraries: Vec<String>,
    material_names: Vec<String>,
    /// The file vertex of each distinct (v, vt, vn) corner.
    corner_vertex: HashMap<(usize, usize, usize), u32>,
    /// The part of each (object, group).
    parts: HashMap<(Option<String>, Option<String>), usize>,
    object: Option<String>,
    group: Option<String>,
    material: Option<usize>,
    /// The part and primitive faces go to, until an `o`, `g` or `usemtl` changes it.
    current: Option<(usize, usize)>,
    corners: Vec<u32>,
}

impl SceneReader<'_> {
    /// Reads one line.
    fn line(&mut self, line: &[u8]) {
        let mut words = tokens(line);
        match words.next() {
            Some(b"v") => {
                let values: Vec<&[u8]> = words.collect();
                self.positions
                    .push(vertex_of(values.iter().copied()).unwrap_or([f32::NAN; 3]));
                self.colours.push((values.len() == 6).then(|| {
                    [3, 4, 5].map(|i| {
                        crate::io::text::parse_f32(values[i])
                            .filter(|c| c.is_finite())
                            .map_or(1.0, |c| c.clamp(0.0, 1.0))
                    })
                }));
            }
            Some(b"vt") => {
                // Never a NaN in the output: what is not a finite number becomes 0.
                let mut number = || {
                    words
                        .next()
                        .and_then(crate::io::text::parse_f32)
                        .filter(|c| c.is_finite())
                        .unwrap_or(0.0)
                };
                // In the library's convention (v from the image's top row).
                let uv = [number(), number()];
                self.uvs
                    .push(crate::io::uv_convention::into_library(Format::Obj, uv));
            }
            Some(b"vn") => self.normals.push(
                vertex_of(words.take(3))
                    .filter(|n| n.iter().all(|c| c.is_finite()))
                    .unwrap_or([0.0; 3]),
            ),
            Some(b"o") => {
                self.object = rest_of(words);
                self.current = None;
            }
            Some(b"g") => {
                self.group = rest_of(words);
                self.current = None;
            }
            Some(b"usemtl") => {
                let names = &mut self.material_names;
                self.material = rest_of(words).map(|name| {
                    names.iter().position(|m| *m == name).unwrap_or_else(|| {
                        names.push(name);
                        names.len() - 1
                    })
                });
                self.current = None;
            }
            Some(b"mtllib") => self.libraries.extend(rest_of(words)),
            Some(b"f") => self.face(words),
            _ => {}
        }
    }

    /// An `f` line: its corners as file vertices (one per distinct `v/vt/vn`), fan-triangulated
    /// into the current part and primitive; a face with a bad vertex is left out.
    fn face<'w>(&mut self, words: impl Iterator<Item = &'w [u8]>) {
        self.corners.clear();
        for corner in words {
            let mut parts = corner.split(|&b| b == b'/');
            let v = parts.next().and_then(|t| resolve(t, self.positions.len()));
            let vt = parts
                .next()
                .filter(|t| !t.is_empty())
                .and_then(|t| resolve(t, self.uvs.len()))
                .filter(|&t| t < self.uvs.len());
            let vn = parts
                .next()
                .filter(|t| !t.is_empty())
                .and_then(|t| resolve(t, self.normals.len()))
                .filter(|&n| n < self.normals.len());
            let Some(v) = v.filter(|&v| v < self.positions.len()) else {
                self.corners.clear();
                break;
            };
            let index = self.file_vertex(v, vt, vn);
            self.scene.uvs |= vt.is_some();
            self.scene.normals |= vn.is_some();
            self.scene.colours |= self.colours[v].is_some();
            self.corners.push(index);
        }
        if self.corners.len() < 3 {
            return;
        }
        let (part, primitive) = self.current_primitive();
        let triangles = &mut self.scene.parts[part].primitives[primitive].triangles;
        let corners = &self.corners;
        for i in 1..corners.len() - 1 {
            triangles.push([corners[0], corners[i], corners[i + 1]]);
        }
    }

    /// The file vertex of corner `v/vt/vn`, made when it is new.
    fn file_vertex(&mut self, v: usize, vt: Option<usize>, vn: Option<usize>) -> u32 {
        let key = (v, vt.unwrap_or(usize::MAX), vn.unwrap_or(usize::MAX));
        let scene = &mut self.scene;
        let (origin, positions, uvs, colours, normals) = (
            self.origin,
            &self.positions,
            &self.uvs,
            &self.colours,
            &self.normals,
        );
        *self.corner_vertex.entry(key).or_insert_with(|| {
            let mut vertex = SceneVertex::new(origin.welded(v), positions[v]);
            if let Some(t) = vt {
                vertex.uv = uvs[t];
            }
            if let Some([r, g, b]) = colours[v] {
                vertex.colour = [r, g, b, 1.0];
            }
            if let Some(n) = vn {
                vertex.normal = normals[n];
                vertex.slot = n;
            }
            scene.vertices.push(vertex);
            (scene.vertices.len() - 1) as u32
        })
    }

    /// The part (of the current object and group) and primitive (of the current material) faces
    /// go to, made when new.
    fn current_primitive(&mut self) -> (usize, usize) {
        if let Some(current) = self.current {
            return current;
        }
        let (object, group, material) = (&self.object, &self.group, self.material);
        let scene = &mut self.scene;
        let key = (object.clone(), group.clone());
        let part = *self.parts.entry(key).or_insert_with(|| {
            scene.parts.push(Part {
                object: object.clone(),
                group: group.clone(),
                primitives: Vec::new(),
            });
            scene.parts.len() - 1
        });
        let primitives = &mut scene.parts[part].primitives;
        let primitive = primitives
            .iter()
            .position(|p| p.material == material)
            .unwrap_or_else(|| {
                primitives.push(Primitive {
                    material,
                    triangles: Vec::new(),
                });
                primitives.len() - 1
            });
        self.current = Some((part, primitive));
        (part, primitive)
    }
}
