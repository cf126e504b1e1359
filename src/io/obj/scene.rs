//! An OBJ file as a [`Scene`] (see [`crate::io::scene`]): its parts, file vertices, normals
//! turned with their faces, and materials ([`super::materials`]).

use super::line::{resolve, rest_of, vertex_of};
use super::materials::read_materials;
use crate::io::origin::Origin;
use crate::io::scene::{Part, Primitive, Scene, SceneVertex};
use crate::io::text::tokens;
use crate::mesh::TriMesh;
use std::collections::HashMap;

/// The OBJ's parts (one per `o`/`g` pair), materials (from its `mtllib` files, read beside it),
/// and file vertices (one per distinct `v/vt/vn` corner), for saving in another format (see
/// [`crate::io::scene`]). Normals turn with their faces to `mesh`'s positions, slot by `vn` line as
/// in [`super::write_back`].
pub(crate) fn scene(bytes: &[u8], origin: &Origin, mesh: &TriMesh) -> Scene {
    let mut scene = Scene {
        groups_under_objects: true,
        ..Scene::default()
    };
    let mut positions: Vec<[f32; 3]> = Vec::with_capacity(origin.raw_vertices);
    let mut colours: Vec<Option<[f32; 3]>> = Vec::with_capacity(origin.raw_vertices);
    let mut uvs: Vec<[f32; 2]> = Vec::new();
    let mut normals: Vec<[f32; 3]> = Vec::new();
    let mut libraries: Vec<String> = Vec::new();
    let mut material_names: Vec<String> = Vec::new();
    let mut corner_vertex: HashMap<(usize, usize, usize), u32> = HashMap::new();
    let mut parts: HashMap<(Option<String>, Option<String>), usize> = HashMap::new();
    let (mut object, mut group, mut material): (Option<String>, Option<String>, Option<usize>) =
        (None, None, None);
    // The part and primitive faces go to, until an `o`, `g` or `usemtl` changes it.
    let mut current: Option<(usize, usize)> = None;
    let mut corners: Vec<u32> = Vec::with_capacity(8);
    for line in bytes.split(|&b| b == b'\n') {
        let mut words = tokens(line);
        match words.next() {
            Some(b"v") => {
                let values: Vec<&[u8]> = words.collect();
                positions.push(vertex_of(values.iter().copied()).unwrap_or([f32::NAN; 3]));
                colours.push((values.len() == 6).then(|| {
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
                uvs.push([number(), number()]);
            }
            Some(b"vn") => normals.push(
                vertex_of(words.take(3))
                    .filter(|n| n.iter().all(|c| c.is_finite()))
                    .unwrap_or([0.0; 3]),
            ),
            Some(b"o") => {
                object = rest_of(words);
                current = None;
            }
            Some(b"g") => {
                group = rest_of(words);
                current = None;
            }
            Some(b"usemtl") => {
                material = rest_of(words).map(|name| {
                    material_names
                        .iter()
                        .position(|m| *m == name)
                        .unwrap_or_else(|| {
                            material_names.push(name);
                            material_names.len() - 1
                        })
                });
                current = None;
            }
            Some(b"mtllib") => libraries.extend(rest_of(words)),
            Some(b"f") => {
                corners.clear();
                for corner in words {
                    let mut parts = corner.split(|&b| b == b'/');
                    let v = parts.next().and_then(|t| resolve(t, positions.len()));
                    let vt = parts
                        .next()
                        .filter(|t| !t.is_empty())
                        .and_then(|t| resolve(t, uvs.len()))
                        .filter(|&t| t < uvs.len());
                    let vn = parts
                        .next()
                        .filter(|t| !t.is_empty())
                        .and_then(|t| resolve(t, normals.len()))
                        .filter(|&n| n < normals.len());
                    let Some(v) = v.filter(|&v| v < positions.len()) else {
                        corners.clear();
                        break;
                    };
                    let key = (v, vt.unwrap_or(usize::MAX), vn.unwrap_or(usize::MAX));
                    let index = *corner_vertex.entry(key).or_insert_with(|| {
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
                    });
                    scene.uvs |= vt.is_some();
                    scene.normals |= vn.is_some();
                    scene.colours |= colours[v].is_some();
                    corners.push(index);
                }
                if corners.len() < 3 {
                    continue;
                }
                let (part, primitive) = *current.get_or_insert_with(|| {
                    let key = (object.clone(), group.clone());
                    let part = *parts.entry(key).or_insert_with(|| {
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
                    (part, primitive)
                });
                let triangles = &mut scene.parts[part].primitives[primitive].triangles;
                for i in 1..corners.len() - 1 {
                    triangles.push([corners[0], corners[i], corners[i + 1]]);
                }
            }
            _ => {}
        }
    }
    scene.materials = read_materials(&material_names, &libraries, origin, &mut scene.warnings);
    scene.drop_degenerate();
    scene.turn_normals(mesh);
    scene
}
