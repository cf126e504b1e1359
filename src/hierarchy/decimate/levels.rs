//! The levels the decimation's passes run on: M0 as the first level, and the level after a
//! pass's collapses (survivors in their order, faces of removed vertices relabelled), each
//! written in parallel chunks whose counts place them.

use super::*;

/// M0 as the first level: the vertices that some face uses (isolated ones are never removed) in
/// Morton order of their positions (quantized to 10 bits per axis in M0's bounding box; ties by
/// id), the faces in order of their first corner's place in that order (ties by id); with the
/// creases' classes and crease neighbours in the same order. `parallel`: sort in chunks and
/// blocks (the same order).
pub(super) fn first_level(mesh: &TriMesh, creases: Option<&Creases>, parallel: bool) -> Level {
    let n = mesh.vertex_count();
    let (lo, hi) = crate::metrics::bounding_box(mesh).unwrap_or_default();
    let scale = (hi - lo).max_element().max(f64::MIN_POSITIVE);
    // Every vertex's key (isolated ones are taken out after the sort, which leaves the others'
    // order as it is: a filtered parallel collect cost more than the codes).
    let keys: Vec<u64> = (0..n)
        .into_par_iter()
        .with_min_len(4096)
        .map(|v| {
            let p = mesh.positions[v].map(f64::from);
            crate::mesh::morton_code(p.into(), lo, scale) << 32 | v as u64
        })
        .collect();
    // Sorted by code (30 bits), ties by id (the keys come in id order and each pass is stable):
    // the low 15 bits of the code, then the high 15; the second pass writes each vertex's
    // place too.
    let digit = |k: u64, shift: u32| (k >> (32 + shift)) as usize & 0x7fff;
    let by_low: Vec<AtomicU64> = (0..n).into_par_iter().map(|_| AtomicU64::new(0)).collect();
    digit_sort(
        &keys,
        |&k| digit(k, 0),
        parallel,
        |slot, &k| {
            by_low[slot].store(k, Relaxed);
        },
    );
    drop(keys);
    let by_low: Vec<u64> = by_low.into_iter().map(AtomicU64::into_inner).collect();
    let (vertex_id, place_of) = (atomics(n, 0), atomics(n, 0));
    digit_sort(
        &by_low,
        |&k| digit(k, 15),
        parallel,
        |slot, &k| {
            vertex_id[slot].store(k as u32, Relaxed);
            place_of[k as u32 as usize].store(slot as u32, Relaxed);
        },
    );
    drop(by_low);
    let mut vertex_id = into_inner(vertex_id);
    let mut level_of = into_inner(place_of);
    let mut used = vec![false; n];
    for t in &mesh.triangles {
        for &c in t {
            used[c as usize] = true;
        }
    }
    if used.contains(&false) {
        vertex_id.retain(|&v| used[v as usize]);
        level_of.fill(NEVER);
        for (i, &v) in vertex_id.iter().enumerate() {
            level_of[v as usize] = i as u32;
        }
    }
    drop(used);
    let (mut offsets, mut cursor) = (Vec::new(), Vec::new());
    // Faces by a counting sort on their first corner's place (stable, so ties stay by id).
    let place: Vec<u32> = mesh
        .triangles
        .par_iter()
        .with_min_len(4096)
        .map(|t| level_of[t[0] as usize])
        .collect();
    let mut face_id = Vec::new();
    bucket_sort(
        place.len(),
        vertex_id.len(),
        parallel,
        |f| [(place[f], f as u32)],
        SortedBuckets {
            offsets: &mut offsets,
            cursor: &mut cursor,
            sorted: &mut face_id,
        },
    );
    drop(place);
    let crease = creases.map_or_else(Vec::new, |creases| {
        let mut crease: Vec<[u32; 2]> = vertex_id
            .iter()
            .map(|&v| match creases.class[v as usize] {
                FeatureClass::Smooth => NO_CREASE,
                FeatureClass::Corner => CORNER,
                FeatureClass::Crease => [NEVER; 2],
            })
            .collect();
        for &[a, b] in &creases.edges {
            let (a, b) = (level_of[a as usize], level_of[b as usize]);
            for (x, y) in [(a, b), (b, a)] {
                let slots = &mut crease[x as usize];
                if *slots != CORNER {
                    let free = if slots[0] == NEVER { 0 } else { 1 };
                    slots[free] = y;
                }
            }
        }
        crease
    });
    Level {
        crease,
        points: vertex_id
            .par_iter()
            .map(|&v| mesh.positions[v as usize])
            .collect(),
        corners: face_id
            .par_iter()
            .map(|&f| mesh.triangles[f as usize].map(|c| level_of[c as usize]))
            .collect(),
        vertex_id,
        face_id,
    }
}

/// The level after the pass's collapses: survivors keep their relative order, faces of removed
/// vertices are relabelled to the targets, and those that degenerate disappear (recorded in
/// `face_removed_in_pass`). `level.corners` is relabelled in place on the way.
///
/// In parallel over consecutive chunks of `chunk` vertices and of `chunk` faces (one chunk of
/// each when `None`): each chunk first counts what it keeps, the running sums of the counts give
/// each chunk its place in the next level, and each chunk then writes its part there, so the
/// next level is the same for any number of threads.
pub(super) fn next_level(
    level: &mut Level,
    state: &mut PassState,
    pass: u32,
    removed: usize,
    face_removed_in_pass: &[AtomicU32],
    chunk: Option<usize>,
    next: &mut Level,
) {
    let n = level.points.len();
    let vertices = n - removed;
    let chunk_len = |len: usize| chunk.unwrap_or(len).max(1);
    let chunk = chunk_len(n);
    let (mark, label) = (&state.mark, &mut state.label);
    let survives = |m: &AtomicU32| m.load(Relaxed) >= LOCKED;
    // Survivors, chunk by chunk: their labels, points and M0 ids.
    let kept: Vec<u32> = mark
        .par_chunks(chunk)
        .map(|marks| marks.iter().filter(|m| survives(m)).count() as u32)
        .collect();
    // (Every entry is written below: survivors get theirs, removed vertices their target's.)
    refill(label, n, NEVER);
    next.points = vec![[0.0; 3]; vertices];
    next.vertex_id = vec![0; vertices];
    let starts = running_starts(&kept);
    mark.par_chunks(chunk)
        .zip(label.par_chunks(chunk))
        .zip(split_by_lengths(&mut next.points, &kept))
        .zip(split_by_lengths(&mut next.vertex_id, &kept))
        .enumerate()
        .for_each(|(c, (((marks, labels), points), ids))| {
            let first = c * chunk;
            let mut slot = 0;
            for (i, (m, l)) in marks.iter().zip(labels).enumerate() {
                if survives(m) {
                    l.store(starts[c] + slot as u32, Relaxed);
                    points[slot] = level.points[first + i];
                    ids[slot] = level.vertex_id[first + i];
                    slot += 1;
                }
            }
        });
    // A removed vertex takes its target's label (a target survives the pass).
    let label_of = |v: u32| label[v as usize].load(Relaxed);
    mark.par_chunks(chunk)
        .zip(label.par_chunks(chunk))
        .for_each(|(marks, labels)| {
            for (m, l) in marks.iter().zip(labels) {
                let m = m.load(Relaxed);
                if m < LOCKED {
                    l.store(label_of(m), Relaxed);
                }
            }
        });
    // Crease neighbours were moved to survivors as the collapses happened.
    next.crease = Vec::new();
    if !level.crease.is_empty() {
        next.crease = vec![NO_CREASE; vertices];
        level
            .crease
            .par_chunks(chunk)
            .zip(mark.par_chunks(chunk))
            .zip(split_by_lengths(&mut next.crease, &kept))
            .for_each(|((creases, marks), out)| {
                let kept = creases.iter().zip(marks).filter(|(_, m)| survives(m));
                for ((&c, _), slot) in kept.zip(out) {
                    *slot = if c == NO_CREASE || c == CORNER {
                        c
                    } else {
                        c.map(label_of)
                    };
                }
            });
    }
    // Faces, relabelled in place; those that degenerate are the removed ones.
    let chunk = chunk_len(level.corners.len());
    let degenerate = |t: &[u32; 3]| t[0] == t[1] || t[1] == t[2] || t[0] == t[2];
    let kept: Vec<u32> = level
        .corners
        .par_chunks_mut(chunk)
        .zip(level.face_id.par_chunks(chunk))
        .map(|(corners, ids)| {
            let mut kept = 0;
            for (t, &f) in corners.iter_mut().zip(ids) {
                *t = t.map(label_of);
                if degenerate(t) {
                    face_removed_in_pass[f as usize].store(pass, Relaxed);
                } else {
                    kept += 1;
                }
            }
            kept
        })
        .collect();
    let faces = kept.iter().map(|&k| k as usize).sum();
    next.corners = vec![[0; 3]; faces];
    next.face_id = vec![0; faces];
    level
        .corners
        .par_chunks(chunk)
        .zip(level.face_id.par_chunks(chunk))
        .zip(split_by_lengths(&mut next.corners, &kept))
        .zip(split_by_lengths(&mut next.face_id, &kept))
        .for_each(|(((corners, ids), out_corners), out_ids)| {
            let kept = corners.iter().zip(ids).filter(|(t, _)| !degenerate(t));
            for (((t, &f), slot), id) in kept.zip(out_corners).zip(out_ids) {
                *slot = *t;
                *id = f;
            }
        });
}
