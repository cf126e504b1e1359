//! Tests of the decimation passes.

use super::*;

/// Pseudo-random draws below a bound, from `seed` (a linear congruential generator).
fn draws(seed: u64) -> impl FnMut(u64) -> u64 {
    let mut state = seed;
    move |below| {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (state >> 33) % below
    }
}

/// The radix sort and its tie-breaking give (cost, M0 id) order: costs with many ties, with
/// digits all share (skipped) and with every digit in use, including infinity.
#[test]
fn cost_order_is_by_cost_then_m0_id() {
    let mut next = draws(99);
    let n = 5000;
    let costs: [Vec<u32>; 3] = [
        // Few values: long runs of ties.
        (0..n).map(|_| (next(7) as f32 * 0.5).to_bits()).collect(),
        // Only the low digit varies.
        (0..n).map(|_| 0x3f80_0000 | next(1 << 11) as u32).collect(),
        // Anything, now and then infinity.
        (0..n)
            .map(|_| match next(50) {
                0 => f32::INFINITY.to_bits(),
                _ => (next(1 << 20) as f32 * 1e-3).to_bits(),
            })
            .collect(),
    ];
    for cost in costs {
        let mut vertex_id: Vec<u32> = (0..n as u32).map(|i| i * 7 % n as u32).collect();
        vertex_id.reverse();
        let level = Level {
            vertex_id,
            ..Level::default()
        };
        let pass = PassState {
            cost,
            ..PassState::default()
        };
        // Every third vertex, as a region's interior would be a part of the level.
        let chosen = (0..n).filter(|v| v % 3 != 1);
        let mut expected: Vec<u32> = chosen.clone().map(|v| v as u32).collect();
        expected.sort_by_key(|&v| (pass.cost[v as usize], level.vertex_id[v as usize]));
        let mut order = Vec::new();
        in_cost_order(chosen, &pass, &level, &mut order, &mut Vec::new());
        assert_eq!(order, expected);
    }
}

/// M0's order: the vertices some face uses by Morton code, ties by id, isolated ones left
/// out; the faces by their first corner's place, ties by id; the same whether sorted in
/// chunks on several threads or on one.
#[test]
fn first_level_orders_used_vertices_by_code_then_id_on_any_thread_count() {
    // Positions from a few values, so many vertices share a code; every seventh vertex is
    // isolated (some share their code with used ones). The faces need no shape here.
    let mut next = draws(12345);
    let n = 6000u32;
    let positions: Vec<[f32; 3]> = (0..n)
        .map(|_| [0; 3].map(|_| next(5) as f32 * 0.25))
        .collect();
    let used: Vec<u32> = (0..n).filter(|v| v % 7 != 3).collect();
    let triangles: Vec<[u32; 3]> = (0..9000)
        .map(|_| loop {
            let t = [0; 3].map(|_| used[next(used.len() as u64) as usize]);
            if t[0] != t[1] && t[1] != t[2] && t[0] != t[2] {
                break t;
            }
        })
        .collect();
    let mesh = TriMesh::new(positions, triangles);
    let (lo, hi) = crate::metrics::bounding_box(&mesh).unwrap();
    let scale = (hi - lo).max_element();
    let code = |v: u32| {
        let p = mesh.positions[v as usize].map(f64::from);
        crate::mesh::morton_code(p.into(), lo, scale)
    };
    // (A few of `used` may have been drawn by no face.)
    let mut in_faces = vec![false; n as usize];
    for &c in mesh.triangles.iter().flatten() {
        in_faces[c as usize] = true;
    }
    let mut expected: Vec<u32> = (0..n).filter(|&v| in_faces[v as usize]).collect();
    expected.sort_by_key(|&v| (code(v), v));
    let mut place = vec![NEVER; n as usize];
    for (i, &v) in expected.iter().enumerate() {
        place[v as usize] = i as u32;
    }
    let mut faces: Vec<u32> = (0..mesh.face_count() as u32).collect();
    faces.sort_by_key(|&f| (place[mesh.triangles[f as usize][0] as usize], f));

    let serial = first_level(&mesh, None, false);
    assert_eq!(serial.vertex_id, expected);
    assert_eq!(serial.face_id, faces);
    for (corners, &f) in serial.corners.iter().zip(&faces) {
        assert_eq!(
            *corners,
            mesh.triangles[f as usize].map(|c| place[c as usize])
        );
    }
    for threads in [1, 2, 3, 5] {
        let level = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| first_level(&mesh, None, true));
        assert_eq!(level.vertex_id, serial.vertex_id, "{threads} threads");
        assert_eq!(level.face_id, serial.face_id, "{threads} threads");
        assert_eq!(level.corners, serial.corners, "{threads} threads");
        assert_eq!(level.points, serial.points, "{threads} threads");
    }
}
