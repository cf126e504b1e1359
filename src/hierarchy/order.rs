//! M0 numbered by level: the decimation's output (which pass removed each vertex and face, in
//! M0's numbering) turned into the hierarchy's internal order, vertices and faces by the pass
//! that removed them, latest first, so that level i is a prefix of every array.

use super::decimate::{atomics, into_inner, BuildOutput, NEVER};
use super::{Hierarchy, NEXT_HIERARCHY_ID};
use crate::fairing::creases::Creases;
use crate::mesh::TriMesh;
use rayon::prelude::*;
use std::sync::atomic::Ordering;

/// The hierarchy from the decimation's output: M0 (`mesh`) numbered by level (vertices and
/// faces by the pass that removed them, latest first), with every per-vertex array in that
/// order. `levels_mesh` is the mesh that was decimated (`mesh` without its `loose` triangles).
pub(super) fn in_level_order(
    mesh: &TriMesh,
    levels_mesh: &TriMesh,
    loose: Vec<u32>,
    built: BuildOutput,
    creases: Option<Creases>,
    setup_ms: f64,
) -> Hierarchy {
    let finishing = crate::clock::Instant::now();
    let passes = built.pass_ms.len();

    // Internal order: by pass of removal, latest (or never) first; ties by id.
    let ByPass {
        order,
        rank,
        level_sizes: level_vertices,
    } = by_pass(&built.removed_in_pass, passes, true);
    let ByPass {
        order: face_order,
        level_sizes: level_faces,
        ..
    } = by_pass(&built.face_removed_in_pass, passes, false);
    // Gathers in M0's order (parallel, as they mostly wait on memory).
    let positions = order
        .par_iter()
        .with_min_len(4096)
        .map(|&v| mesh.positions[v as usize])
        .collect();
    let triangles = face_order
        .par_iter()
        .with_min_len(4096)
        .map(|&f| levels_mesh.triangles[f as usize].map(|c| rank[c as usize]))
        .collect();
    let face_order = with_loose_faces(face_order, &loose, mesh.face_count());
    let target = targets_in_order(&order, &rank, &built.target);
    let six_split_volume = order
        .par_iter()
        .with_min_len(4096)
        .map(|&v| built.six_split_volume[v as usize])
        .collect();
    let (feature_class, crease_edges) = match creases {
        Some(creases) => (
            order.iter().map(|&v| creases.class[v as usize]).collect(),
            creases
                .edges
                .iter()
                .map(|e| e.map(|c| rank[c as usize]))
                .collect(),
        ),
        None => (Vec::new(), Vec::new()),
    };
    let mut level_ms = vec![setup_ms + finishing.elapsed().as_secs_f64() * 1e3];
    level_ms.extend_from_slice(&built.pass_ms);

    Hierarchy {
        base: mesh.clone(),
        id: NEXT_HIERARCHY_ID.fetch_add(1, Ordering::Relaxed),
        order,
        rank,
        positions,
        triangles,
        face_order,
        target,
        six_split_volume,
        level_vertices,
        level_faces,
        level_ms,
        feature_class,
        crease_edges,
        non_manifold: built.non_manifold,
        loose,
    }
}

/// Every vertex's collapse target (`target`, M0's numbering; `NEVER` for none) in the internal
/// order (`order`, with `rank` its inverse), as an internal id.
fn targets_in_order(order: &[u32], rank: &[u32], target: &[u32]) -> Vec<u32> {
    order
        .par_iter()
        .with_min_len(4096)
        .map(|&v| {
            let k = target[v as usize];
            if k == NEVER {
                NEVER
            } else {
                rank[k as usize]
            }
        })
        .collect()
}

/// The levels mesh's faces in level order (`face_order`, ids of the mesh without its `loose`
/// faces) as ids of M0's `face_count` faces.
fn with_loose_faces(face_order: Vec<u32>, loose: &[u32], face_count: usize) -> Vec<u32> {
    if loose.is_empty() {
        return face_order;
    }
    let mut is_loose = vec![false; face_count];
    for &f in loose {
        is_loose[f as usize] = true;
    }
    let kept: Vec<u32> = (0..face_count as u32)
        .filter(|&f| !is_loose[f as usize])
        .collect();
    face_order.iter().map(|&f| kept[f as usize]).collect()
}

/// Vertices (or faces) ordered by the pass that removed them, latest first and those never
/// removed before all; ties by id.
struct ByPass {
    /// Ids in that order.
    order: Vec<u32>,
    /// Place of each id in `order` (empty unless asked for).
    rank: Vec<u32>,
    /// `level_sizes[i]`: how many were not removed in passes `0..i`, for `i` in `0..=passes`.
    level_sizes: Vec<u32>,
}

/// A stable counting sort of the ids by `removed_in_pass` (`NEVER`, or a pass below `passes`),
/// in parallel over chunks of ids: each chunk counts its ids per pass, the counts give each chunk
/// its places, and each chunk places its ids (and writes their ranks, which are its own), so the
/// order is the same for any number of threads.
fn by_pass(removed_in_pass: &[u32], passes: usize, with_rank: bool) -> ByPass {
    const CHUNK: usize = 1 << 15;
    // Bucket 0 for survivors, `passes - p` for ids removed in pass p.
    let bucket = |p: u32| if p == NEVER { 0 } else { passes - p as usize };
    let counts: Vec<Vec<u32>> = removed_in_pass
        .par_chunks(CHUNK)
        .map(|chunk| {
            let mut count = vec![0u32; passes + 1];
            for &p in chunk {
                count[bucket(p)] += 1;
            }
            count
        })
        .collect();
    // Each chunk's first place in each bucket.
    let mut next = vec![0u32; passes + 1];
    for count in &counts {
        for (n, c) in next.iter_mut().zip(count) {
            *n += c;
        }
    }
    let totals = next.clone();
    let mut sum = 0;
    for n in &mut next {
        (*n, sum) = (sum, sum + *n);
    }
    let starts: Vec<Vec<u32>> = counts
        .iter()
        .map(|count| {
            let start = next.clone();
            for (n, c) in next.iter_mut().zip(count) {
                *n += c;
            }
            start
        })
        .collect();
    let order = atomics(removed_in_pass.len(), 0);
    let mut rank = if with_rank {
        vec![0u32; removed_in_pass.len()]
    } else {
        Vec::new()
    };
    let rank_chunks: Vec<Option<&mut [u32]>> = if with_rank {
        rank.chunks_mut(CHUNK).map(Some).collect()
    } else {
        (0..starts.len()).map(|_| None).collect()
    };
    removed_in_pass
        .par_chunks(CHUNK)
        .zip(starts)
        .zip(rank_chunks)
        .enumerate()
        .for_each(|(c, ((chunk, mut slot), mut rank))| {
            for (i, &p) in chunk.iter().enumerate() {
                let slot = &mut slot[bucket(p)];
                order[*slot as usize].store((c * CHUNK + i) as u32, Ordering::Relaxed);
                if let Some(rank) = rank.as_mut() {
                    rank[i] = *slot;
                }
                *slot += 1;
            }
        });
    // Level i keeps the survivors and the ids removed in passes i and later: buckets
    // `0..=passes - i`.
    let level_sizes = (0..=passes)
        .map(|i| totals[..=passes - i].iter().sum())
        .collect();
    ByPass {
        // (Atomics only so that the chunks can place their ids at once; the same layout, so
        // this reuses the memory.)
        order: into_inner(order),
        rank,
        level_sizes,
    }
}
