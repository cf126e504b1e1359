//! Invariants of the hierarchy on small hand-built meshes.

use super::*;
use crate::mesh::{subdivide_loop, Topology};
use crate::NoProgress;

fn octahedron() -> TriMesh {
    crate::mesh::fixtures::octahedron(1.0)
}

/// A sphere-like closed mesh: the octahedron subdivided `times` times, pushed onto the sphere.
fn sphere(times: usize) -> TriMesh {
    let mut mesh = octahedron();
    for _ in 0..times {
        mesh = subdivide_loop(&mesh);
    }
    for p in &mut mesh.positions {
        let l = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
        *p = p.map(|c| c / l);
    }
    mesh
}

/// An open, gently curved grid of `n x n` quads, each split in two.
fn grid(n: u32) -> TriMesh {
    let mut positions = Vec::new();
    for y in 0..=n {
        for x in 0..=n {
            let (fx, fy) = (x as f32 / n as f32, y as f32 / n as f32);
            positions.push([fx, fy, 0.3 * (fx * 3.0).sin() * (fy * 2.0).cos()]);
        }
    }
    let mut triangles = Vec::new();
    let at = |x: u32, y: u32| y * (n + 1) + x;
    for y in 0..n {
        for x in 0..n {
            triangles.push([at(x, y), at(x + 1, y), at(x + 1, y + 1)]);
            triangles.push([at(x, y), at(x + 1, y + 1), at(x, y + 1)]);
        }
    }
    TriMesh::new(positions, triangles)
}

fn check_levels(mesh: &TriMesh, options: &HierarchyOptions) -> Hierarchy {
    let h = build_hierarchy(mesh, options, &mut NoProgress).unwrap();
    let base = Topology::build(mesh);
    assert!(h.level_count() > 1, "no level was built");
    for level in 0..h.level_count() {
        let m = h.level_mesh(level);
        let topo = Topology::build(&m);
        assert!(
            topo.is_oriented_manifold(),
            "level {level} is not an oriented manifold"
        );
        assert_eq!(
            topo.euler_characteristic(),
            base.euler_characteristic(),
            "level {level}"
        );
        assert_eq!(
            topo.boundary_loops.len(),
            base.boundary_loops.len(),
            "level {level}"
        );
        assert_eq!(m.face_count(), h.level_info(level).faces);
        // Removed vertices are pairwise non-adjacent in the level they are removed from.
        let removed_from = h.level_info(level + 1).vertices as u32;
        if level + 1 < h.level_count() {
            for c in h.collapses(level) {
                assert!(topo.neighbors(c.vertex).iter().all(|&u| u < removed_from));
                assert!(topo.neighbors(c.vertex).contains(&c.target));
            }
        }
    }
    h
}

/// Within each level's share of the internal order (the vertices and faces one pass removed,
/// or those no pass removed), vertices follow the Morton order of their M0 positions and faces
/// that of their first corner (ties by M0 id), as the decimation's first level has them: every
/// level's arrays then keep a vertex's neighbours near it in memory. Ties by M0 id alone, the
/// subdivided sphere's split vertices come before the corners near them.
#[test]
fn each_level_keeps_its_vertices_and_faces_in_morton_order() {
    let mut mesh = sphere(3);
    // An isolated vertex is in no face: it comes last of those no pass removed.
    mesh.positions.push([0.0, 0.0, 0.0]);
    let h = build_hierarchy(&mesh, &HierarchyOptions::default(), &mut NoProgress).unwrap();
    let (lo, hi) = crate::metrics::bounding_box(&mesh).unwrap();
    let extent = (hi - lo).max_element();
    let key = |v: u32| {
        let p = mesh.positions[v as usize].map(f64::from);
        (crate::mesh::morton_code(p.into(), lo, extent), v)
    };
    let shares = |sizes: &[u32]| -> Vec<std::ops::Range<usize>> {
        // The survivors' share, then each pass's, coarsest first.
        let coarsest = std::iter::once(0..sizes[sizes.len() - 1] as usize);
        let passes = (0..sizes.len() - 1)
            .rev()
            .map(|level| sizes[level + 1] as usize..sizes[level] as usize);
        coarsest.chain(passes).collect()
    };
    let isolated = mesh.vertex_count() as u32 - 1;
    let survivors = h.level_vertices[h.level_vertices.len() - 1] as usize;
    assert_eq!(h.order[survivors - 1], isolated);
    let mut ordered_shares = 0;
    for share in shares(&h.level_vertices) {
        let ids: Vec<u32> = h.order[share]
            .iter()
            .copied()
            .filter(|&v| v != isolated)
            .collect();
        assert!(ids.windows(2).all(|w| key(w[0]) < key(w[1])), "{ids:?}");
        ordered_shares += usize::from(ids.len() > 1);
    }
    for share in shares(&h.level_faces) {
        let firsts: Vec<(u64, u32)> = h.face_order[share]
            .iter()
            .map(|&f| key(mesh.triangles[f as usize][0]))
            .collect();
        assert!(firsts.windows(2).all(|w| w[0] <= w[1]), "{firsts:?}");
    }
    assert!(ordered_shares > 2, "{ordered_shares}");
}

/// A level for a file lists its vertices and faces in M0's order, whatever the internal order:
/// level 0 is M0 as it came in, and every level's origins ascend.
#[test]
fn levels_for_files_keep_m0s_order_and_level_0_is_m0() {
    let mesh = sphere(3);
    let h = build_hierarchy(&mesh, &HierarchyOptions::default(), &mut NoProgress).unwrap();
    let (level_0, vertex_origin, face_origin) = h.level_for_export(0);
    assert_eq!(level_0.positions, mesh.positions);
    assert_eq!(level_0.triangles, mesh.triangles);
    assert!(vertex_origin
        .iter()
        .copied()
        .eq(0..mesh.vertex_count() as u32));
    assert!(face_origin.iter().copied().eq(0..mesh.face_count() as u32));
    for level in 1..h.level_count() {
        let (coarse, vertex_origin, face_origin) = h.level_for_export(level);
        assert!(
            vertex_origin.windows(2).all(|w| w[0] < w[1]),
            "level {level}"
        );
        assert!(face_origin.windows(2).all(|w| w[0] < w[1]), "level {level}");
        for (p, &v) in coarse.positions.iter().zip(&vertex_origin) {
            assert_eq!(*p, mesh.positions[v as usize], "level {level}");
        }
        // The same faces as the level in internal order, corner for corner, by M0 ids.
        let internal = h.level_mesh(level);
        let (internal_vertices, internal_faces) = h.level_origins(level);
        let mut expected: Vec<(u32, [u32; 3])> = internal
            .triangles
            .iter()
            .zip(&internal_faces)
            .map(|(t, &f)| (f, t.map(|c| internal_vertices[c as usize])))
            .collect();
        expected.sort_unstable();
        let written: Vec<(u32, [u32; 3])> = coarse
            .triangles
            .iter()
            .zip(&face_origin)
            .map(|(t, &f)| (f, t.map(|c| vertex_origin[c as usize])))
            .collect();
        assert_eq!(written, expected, "level {level}");
    }
}

#[test]
fn closed_sphere_levels_stay_manifold_and_coarsen() {
    let mesh = sphere(3);
    let options = HierarchyOptions {
        min_vertices: 10,
        ..Default::default()
    };
    let h = check_levels(&mesh, &options);
    assert!(h.level_info(h.coarsest_level()).vertices < 60);
}

#[test]
fn open_grid_keeps_its_boundary_loop() {
    let mesh = grid(12);
    let h = check_levels(
        &mesh,
        &HierarchyOptions {
            min_vertices: 8,
            ..Default::default()
        },
    );
    assert!(h.level_info(h.coarsest_level()).vertices < 40);
    let kept = check_levels(
        &mesh,
        &HierarchyOptions {
            min_vertices: 8,
            keep_boundary: true,
            ..Default::default()
        },
    );
    let top = kept.level_mesh(kept.coarsest_level());
    let topo = Topology::build(&top);
    assert_eq!(
        topo.boundary_loops[0].len(),
        48,
        "keep_boundary kept every boundary vertex"
    );
}

#[test]
fn cone_volume_is_six_times_each_collapse_volume_change() {
    let mesh = sphere(3);
    let h = build_hierarchy(&mesh, &HierarchyOptions::default(), &mut NoProgress).unwrap();
    for level in 0..2 {
        let mut positions = h.level_positions(level).to_vec();
        positions.truncate(h.level_info(level).vertices);
        let mut triangles = h.level_triangles(level);
        for c in h.collapses(level).collect::<Vec<_>>() {
            let before =
                crate::metrics::signed_volume(&TriMesh::new(positions.clone(), triangles.clone()));
            triangles.retain(|t| !(t.contains(&c.vertex) && t.contains(&c.target)));
            for t in &mut triangles {
                for x in t.iter_mut() {
                    if *x == c.vertex {
                        *x = c.target;
                    }
                }
            }
            let after =
                crate::metrics::signed_volume(&TriMesh::new(positions.clone(), triangles.clone()));
            let change = after - before;
            assert!(
                (6.0 * change + c.six_split_volume as f64).abs() < 1e-5,
                "collapse {c:?}: 6 x volume change {} vs cone {}",
                6.0 * change,
                c.six_split_volume
            );
        }
        let _ = &mut positions;
    }
}

#[test]
fn coarsen_to_top_and_refine_back_restores_m0() {
    for mesh in [sphere(3), grid(10)] {
        let h = build_hierarchy(&mesh, &HierarchyOptions::default(), &mut NoProgress).unwrap();
        let mut cursor = LevelCursor::new(&h);
        while cursor.coarsen(&h) {
            assert_eq!(cursor.triangles, h.level_triangles(cursor.level));
        }
        assert_eq!(cursor.level, h.coarsest_level());
        while cursor.refine(&h) {
            assert_eq!(cursor.triangles, h.level_triangles(cursor.level));
        }
        let restored = cursor.original_triangles(&h);
        let mut expected = vec![[0u32; 3]; mesh.face_count()];
        for (f, t) in restored.iter().enumerate() {
            expected[h.original_face(f as u32) as usize] = *t;
        }
        assert_eq!(expected, mesh.triangles);
    }
}

#[test]
fn non_manifold_vertices_and_their_neighbours_stay_and_the_rest_is_decimated() {
    // Two spheres touching at one vertex (two fans meeting there): that vertex and its
    // neighbours stay in every level, the rest of both spheres is decimated as usual.
    let one = sphere(3);
    let top = one
        .positions
        .iter()
        .enumerate()
        .max_by(|a, b| a.1[2].total_cmp(&b.1[2]))
        .unwrap()
        .0 as u32;
    let n = one.positions.len() as u32;
    let mut positions = one.positions.clone();
    // The second sphere, mirrored above the first's top vertex, shares that vertex.
    let top_z = one.positions[top as usize][2];
    let id = |v: u32| {
        if v == top {
            top
        } else if v < top {
            n + v
        } else {
            n + v - 1
        }
    };
    for (v, p) in one.positions.iter().enumerate() {
        if v as u32 != top {
            positions.push([p[0], p[1], 2.0 * top_z - p[2]]);
        }
    }
    let mut triangles = one.triangles.clone();
    // Mirrored, so each face is reversed to keep the outside out.
    triangles.extend(one.triangles.iter().map(|t| [id(t[0]), id(t[2]), id(t[1])]));
    let mesh = TriMesh::new(positions, triangles);
    let h = build_hierarchy(&mesh, &HierarchyOptions::default(), &mut NoProgress).unwrap();
    assert_eq!(h.non_manifold_vertices(), &[top]);
    let coarsest = h.coarsest_level();
    assert!(
        h.level_info(coarsest).vertices < mesh.vertex_count() / 4,
        "{:?}",
        h.level_info(coarsest)
    );
    let topology = Topology::build(&mesh);
    let mut stay: Vec<u32> = topology.neighbors(top).to_vec();
    stay.push(top);
    for level in 0..=coarsest {
        let kept: std::collections::HashSet<u32> = (0..h.level_info(level).vertices as u32)
            .map(|v| h.original_vertex(v))
            .collect();
        for &v in &stay {
            assert!(kept.contains(&v), "vertex {v} left at level {level}");
        }
    }
    // The three triangles on one edge, kept whole: every vertex is on it or beside it, nothing
    // collapses.
    let fin = crate::mesh::fixtures::three_triangles_on_one_edge();
    let whole = HierarchyOptions::default().with_leave_out_loose_triangles(false);
    let h = build_hierarchy(&fin, &whole, &mut NoProgress).unwrap();
    assert_eq!(h.coarsest_level(), 0);
    assert_eq!(h.non_manifold_vertices().len(), 2);
    assert!(h.loose_triangles().is_empty());
    // By default one of them is a loose fin, left out of the levels: the other two are a
    // manifold strip.
    let h = build_hierarchy(&fin, &HierarchyOptions::default(), &mut NoProgress).unwrap();
    assert_eq!(h.loose_triangles().len(), 1);
    assert!(h.non_manifold_vertices().is_empty());
    assert_eq!(h.level_info(0).faces, 2);
    assert_eq!(h.base_mesh(), &fin);
}

#[test]
fn tetrahedron_is_not_collapsed_and_cancel_stops() {
    let tetra = TriMesh::new(
        vec![[0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [0., 0., 1.]],
        vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
    );
    let h = build_hierarchy(
        &tetra,
        &HierarchyOptions {
            min_vertices: 0,
            ..Default::default()
        },
        &mut NoProgress,
    )
    .unwrap();
    assert_eq!(h.level_count(), 1);

    let mesh = sphere(5);
    let mut cancel = |_f: f32| false;
    assert!(matches!(
        build_hierarchy(&mesh, &HierarchyOptions::default(), &mut cancel),
        Err(HierarchyError::Cancelled)
    ));
}

#[test]
fn same_hierarchy_on_one_thread_and_on_several() {
    // Large enough that the parallel parts of a pass are split between threads.
    let mut mesh = sphere(6);
    for (i, p) in mesh.positions.iter_mut().enumerate() {
        let bump = 1.0 + 0.01 * ((i * 7919 % 101) as f32 / 101.0);
        *p = p.map(|c| c * bump);
    }
    let one = same_on_thread_counts(&mesh, &HierarchyOptions::default(), &[2, 3]);
    assert!(one.level_count() > 3);
}

/// The hierarchy of `mesh` built on one thread, after checking that it is built bit for bit the
/// same on each of `threads`.
fn same_on_thread_counts(
    mesh: &TriMesh,
    options: &HierarchyOptions,
    threads: &[usize],
) -> Hierarchy {
    let build_on = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| build_hierarchy(mesh, options, &mut NoProgress))
            .unwrap()
    };
    let one = build_on(1);
    for &threads in threads {
        let several = build_on(threads);
        assert_eq!(several.vertex_order(), one.vertex_order());
        assert_eq!(several.level_count(), one.level_count());
        for level in 0..one.level_count() {
            assert_eq!(several.level_info(level), one.level_info(level));
            assert_eq!(several.level_triangles(level), one.level_triangles(level));
        }
        for v in 0..mesh.vertex_count() as u32 {
            assert_eq!(several.collapse_target(v), one.collapse_target(v));
            assert_eq!(
                several.six_split_volume(v).to_bits(),
                one.six_split_volume(v).to_bits()
            );
        }
    }
    one
}

/// Small regions, so that meshes of a few thousand vertices are visited in regions.
fn in_small_regions(options: HierarchyOptions) -> HierarchyOptions {
    HierarchyOptions {
        regions: decimate::RegionSize {
            min: 128,
            max_count: 64,
        },
        ..options
    }
}

#[test]
fn levels_visited_in_regions_are_valid_and_the_same_on_any_thread_count() {
    let mut mesh = sphere(5);
    for (i, p) in mesh.positions.iter_mut().enumerate() {
        let bump = 1.0 + 0.02 * ((i * 7919 % 101) as f32 / 101.0);
        *p = p.map(|c| c * bump);
    }
    let options = in_small_regions(HierarchyOptions::default());
    let one = same_on_thread_counts(&mesh, &options, &[2, 3, 5]);
    // Every level an oriented manifold of the same topology, removals independent.
    let checked = check_levels(&mesh, &options);
    assert_eq!(checked.vertex_order(), one.vertex_order());
    // (The regions were used: one vertex at a time visits in another order.)
    let sequential = build_hierarchy(&mesh, &HierarchyOptions::default(), &mut NoProgress).unwrap();
    assert_ne!(sequential.vertex_order(), one.vertex_order());
}

#[test]
fn creases_survive_every_level_visited_in_regions() {
    let mesh = crate::mesh::shapes::cuboid([2.0, 1.0, 0.5], 0.04);
    let options = in_small_regions(
        HierarchyOptions::default().with_creases(Some(crate::fairing::CreaseOptions::default())),
    );
    let h = check_levels(&mesh, &options);
    assert!(h.crease_edges().len() > 100);
    for level in 0..h.level_count() {
        let creases = h.level_creases(level).expect("creases kept");
        let topology = Topology::build(&h.level_mesh(level));
        for [a, b] in creases.edges {
            assert!(
                topology.neighbors(a).contains(&b),
                "level {level}: crease edge {a}-{b} is no edge of the level"
            );
        }
    }
}

#[test]
fn a_hierarchy_read_back_from_its_bytes_is_the_same_hierarchy() {
    let mesh = crate::bundled::load_bunny(&crate::io::LoadOptions::default())
        .unwrap()
        .mesh;
    let built = build_hierarchy(&mesh, &HierarchyOptions::default(), &mut NoProgress).unwrap();
    let bytes = built.to_bytes();
    let back = Hierarchy::from_bytes(&bytes).unwrap();
    assert_ne!(back.id, built.id);
    assert_eq!(back.to_bytes(), bytes);
    assert_eq!(back.level_count(), built.level_count());
    let coarsest = built.coarsest_level();
    assert_eq!(back.level_mesh(coarsest), built.level_mesh(coarsest));
    assert_eq!(back.base_mesh(), built.base_mesh());
    // Cut short, another layout, or an id out of range: an error, never a panic.
    for cut in [0, 7, 8, 100, bytes.len() / 2, bytes.len() - 1] {
        assert!(
            Hierarchy::from_bytes(&bytes[..cut]).is_err(),
            "cut at {cut}"
        );
    }
    let mut other = bytes.clone();
    other[7] = b'9';
    assert!(Hierarchy::from_bytes(&other).is_err());
    let mut bad = bytes;
    // The first triangle's first corner of M0 (after the header, the positions and the count).
    let at = 8 + 8 + mesh.positions.len() * 12 + 8;
    bad[at..at + 4].copy_from_slice(&u32::MAX.to_le_bytes());
    let error = Hierarchy::from_bytes(&bad).unwrap_err().to_string();
    assert!(error.contains("out of range"), "{error}");
}
