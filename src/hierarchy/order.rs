//! M0 numbered by level: the decimation's output (which pass removed each vertex and face, in
//! M0's numbering) turned into the hierarchy's internal order, vertices and faces by the pass
//! that removed them, latest first, so that level i is a prefix of every array. Within a pass
//! they keep the order the decimation's first level gave them (Morton order of the positions,
//! faces by their first corner): every level's arrays then hold a vertex's neighbours near it,
//! where ties by M0 id scattered them: a start-level slider step on a noisy 1.2M-face scan,
//! whose passes over the finer levels and M0 wait on memory, took 1.3-1.9 s with ties by id and
//! takes 0.8-1.2 s in this order.

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

    // Internal order: by pass of removal, latest (or never) first; ties in the first level's
    // Morton order (isolated vertices last, by id).
    let ByPass {
        order,
        rank,
        level_sizes: level_vertices,
    } = by_pass(
        &built.removed_in_pass,
        passes,
        true,
        &with_isolated(built.vertex_sequence, mesh.vertex_count()),
    );
    let ByPass {
        order: face_order,
        level_sizes: level_faces,
        ..
    } = by_pass(
        &built.face_removed_in_pass,
        passes,
        false,
        &built.face_sequence,
    );
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

/// `sequence` (ids some face uses, each once) followed by the ids of `0..count` it leaves out
/// (isolated vertices), ascending.
fn with_isolated(mut sequence: Vec<u32>, count: usize) -> Vec<u32> {
    if sequence.len() < count {
        let mut listed = vec![false; count];
        for &v in &sequence {
            listed[v as usize] = true;
        }
        sequence.extend((0..count as u32).filter(|&v| !listed[v as usize]));
    }
    sequence
}

/// Vertices (or faces) ordered by the pass that removed them, latest first and those never
/// removed before all; ties in the first level's order.
struct ByPass {
    /// Ids in that order.
    order: Vec<u32>,
    /// Place of each id in `order` (empty unless asked for).
    rank: Vec<u32>,
    /// `level_sizes[i]`: how many were not removed in passes `0..i`, for `i` in `0..=passes`.
    level_sizes: Vec<u32>,
}

/// [`ByPass`] of the ids of `sequence` (each once), in its order within a pass: a stable
/// counting sort by `removed_in_pass` (`NEVER`, or a pass below `passes`), in parallel over
/// chunks of `sequence`: each chunk counts its ids per pass, the counts give each chunk its
/// places, and each chunk places its ids (and writes their ranks), so the order is the same for
/// any number of threads.
fn by_pass(removed_in_pass: &[u32], passes: usize, with_rank: bool, sequence: &[u32]) -> ByPass {
    const CHUNK: usize = 1 << 15;
    debug_assert_eq!(sequence.len(), removed_in_pass.len());
    // Bucket 0 for survivors, `passes - p` for ids removed in pass p.
    let bucket = |id: u32| match removed_in_pass[id as usize] {
        NEVER => 0,
        p => passes - p as usize,
    };
    let counts: Vec<Vec<u32>> = sequence
        .par_chunks(CHUNK)
        .map(|chunk| {
            let mut count = vec![0u32; passes + 1];
            for &id in chunk {
                count[bucket(id)] += 1;
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
    let order = atomics(sequence.len(), 0);
    let rank = atomics(if with_rank { sequence.len() } else { 0 }, 0);
    sequence
        .par_chunks(CHUNK)
        .zip(starts)
        .for_each(|(chunk, mut slot)| {
            for &id in chunk {
                let slot = &mut slot[bucket(id)];
                order[*slot as usize].store(id, Ordering::Relaxed);
                if with_rank {
                    rank[id as usize].store(*slot, Ordering::Relaxed);
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
        rank: into_inner(rank),
        level_sizes,
    }
}
