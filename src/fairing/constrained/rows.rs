//! The weight rows' table: every one-ring entry's row (the weights of a neighbour's umbrella
//! mean, position and anchor) compared bit for bit and kept once, each entry holding the index of
//! its row (a mesh has a few hundred distinct rows; an index is a fraction of a row's bytes), the
//! rows numbered in order of first use so that the kernel reads the table in order.

use super::kernel::EntryWeightIndex;
use crate::mesh::PositionHasher;
use rayon::prelude::*;
use std::collections::HashMap;
use std::hash::BuildHasherDefault;

pub(super) type RowMap = HashMap<[u32; 3], u32, BuildHasherDefault<PositionHasher>>;

/// A weight row's key: its three weights, bit for bit (the fourth lane is always 0).
pub(super) fn row_key(row: &[f32; 4]) -> [u32; 3] {
    [row[0].to_bits(), row[1].to_bits(), row[2].to_bits()]
}

/// One chunk of rows deduplicated against a table of its own: each row's index among the
/// chunk's distinct rows, and those rows in order of first appearance.
pub(super) fn deduplicate_chunk(rows: &[[f32; 4]]) -> (Vec<u32>, Vec<[f32; 4]>) {
    let mut distinct = Vec::new();
    let mut slot = RowMap::default();
    let index = rows
        .iter()
        .map(|row| {
            *slot.entry(row_key(row)).or_insert_with(|| {
                distinct.push(*row);
                (distinct.len() - 1) as u32
            })
        })
        .collect();
    (index, distinct)
}

/// Consecutive chunks deduplicated by [`deduplicate_chunk`], joined: the distinct rows of them
/// all, numbered in chunk order (which is the order of first appearance over the whole
/// sequence), and every row's index among them, in order.
pub(super) fn join_deduplicated(
    mut local: Vec<(Vec<u32>, Vec<[f32; 4]>)>,
) -> (Vec<[f32; 4]>, Vec<u32>) {
    let mut distinct: Vec<[f32; 4]> = Vec::new();
    let mut slot = RowMap::default();
    let global_of_local: Vec<Vec<u32>> = local
        .iter()
        .map(|(_, rows)| {
            rows.iter()
                .map(|row| {
                    *slot.entry(row_key(row)).or_insert_with(|| {
                        distinct.push(*row);
                        (distinct.len() - 1) as u32
                    })
                })
                .collect()
        })
        .collect();
    local
        .par_iter_mut()
        .zip(&global_of_local)
        .for_each(|((index, _), global)| {
            for i in index.iter_mut() {
                *i = global[*i as usize];
            }
        });
    let index = local.into_iter().flat_map(|(index, _)| index).collect();
    (distinct, index)
}

/// Two-byte indices where the rows allow.
pub(super) fn narrowed(distinct: usize, index: Vec<u32>) -> EntryWeightIndex {
    if distinct <= 1 << 16 {
        EntryWeightIndex::Narrow(index.into_par_iter().map(|i| i as u16).collect())
    } else {
        EntryWeightIndex::Wide(index)
    }
}

/// The distinct rows of `rows` (compared bit for bit) in order of first appearance, and each
/// row's index among them. Chunks are deduplicated in parallel against small local tables, then
/// their distinct rows are numbered in chunk order, which is the order of first appearance.
#[cfg(test)]
fn deduplicate_rows(rows: &[[f32; 4]]) -> (Vec<[f32; 4]>, EntryWeightIndex) {
    const ROWS_PER_CHUNK: usize = 1 << 16;
    let local = rows
        .par_chunks(ROWS_PER_CHUNK)
        .map(deduplicate_chunk)
        .collect();
    let (distinct, index) = join_deduplicated(local);
    let index = narrowed(distinct.len(), index);
    (distinct, index)
}

/// The rows `rows` (distinct) renumbered in order of their first use in `index`, with `index`
/// rewritten to the new numbers: what [`deduplicate_rows`] gives for the rows `index` picks, in
/// that order, without making those rows (2 or 4 bytes per entry instead of 16).
pub(super) fn renumber_by_first_use(
    rows: &[[f32; 4]],
    mut index: Vec<u32>,
) -> (Vec<[f32; 4]>, EntryWeightIndex) {
    let mut new_of_old = vec![u32::MAX; rows.len()];
    let mut renumbered = Vec::new();
    for i in index.iter_mut() {
        let slot = &mut new_of_old[*i as usize];
        if *slot == u32::MAX {
            *slot = renumbered.len() as u32;
            renumbered.push(rows[*i as usize]);
        }
        *i = *slot;
    }
    let index = narrowed(renumbered.len(), index);
    (renumbered, index)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::fixtures::Rng;

    /// The set-up deduplicates the weight rows in the mesh's order and renumbers them in the
    /// internal order: that must be exactly what deduplicating the permuted rows gives (the
    /// same table, in the same order, and the same index), with narrow and wide indices.
    #[test]
    fn rows_deduplicated_then_renumbered_are_the_permuted_rows_deduplicated() {
        let mut rng = Rng(7);
        for distinct in [37usize, 70_001] {
            let rows: Vec<[f32; 4]> = (0..150_000)
                .map(|_| {
                    let i = (rng.next() * distinct as f64) as usize;
                    [i as f32, 0.25 * i as f32, -(i as f32), 0.0]
                })
                .collect();
            // A permutation of the entries (the internal order moves whole rings; any
            // permutation must do).
            let mut order: Vec<usize> = (0..rows.len()).collect();
            for i in (1..order.len()).rev() {
                order.swap(i, (rng.next() * (i + 1) as f64) as usize);
            }
            let permuted: Vec<[f32; 4]> = order.iter().map(|&e| rows[e]).collect();
            let expected = deduplicate_rows(&permuted);

            let (mesh_rows, mesh_index) = deduplicate_rows(&rows);
            let wide = |index: &EntryWeightIndex| -> Vec<u32> {
                match index {
                    EntryWeightIndex::Narrow(i) => i.iter().map(|&k| k as u32).collect(),
                    EntryWeightIndex::Wide(i) => i.clone(),
                }
            };
            let mesh_index = wide(&mesh_index);
            let permuted_index = order.iter().map(|&e| mesh_index[e]).collect();
            let got = renumber_by_first_use(&mesh_rows, permuted_index);
            // The mesh-order table is in another order (else the renumbering would be moot).
            assert_ne!(mesh_rows, expected.0);
            assert_eq!(got.0, expected.0, "{distinct} distinct rows");
            assert_eq!(got.1, expected.1, "{distinct} distinct rows");
        }
    }

    #[test]
    fn deduplicated_rows_map_back_to_every_row_with_either_index_width() {
        let row = |i: usize| [i as f32, 0.5 * i as f32, -(i as f32), 0.0];
        // Few distinct rows, repeated across the parallel chunks: two-byte indices.
        let rows: Vec<[f32; 4]> = (0..200_000).map(|i| row(i % 37)).collect();
        let (distinct, index) = deduplicate_rows(&rows);
        assert_eq!(distinct.len(), 37);
        // First appearance order.
        assert!(distinct.iter().enumerate().all(|(i, d)| *d == row(i)));
        let EntryWeightIndex::Narrow(index) = index else {
            panic!("37 rows need no wide index");
        };
        assert!(rows
            .iter()
            .zip(&index)
            .all(|(r, &i)| distinct[i as usize] == *r));
        // More than 65536 distinct rows: four-byte indices.
        let rows: Vec<[f32; 4]> = (0..150_000).map(|i| row((i * 7) % 70_001)).collect();
        let (distinct, index) = deduplicate_rows(&rows);
        assert_eq!(distinct.len(), 70_001);
        let EntryWeightIndex::Wide(index) = index else {
            panic!("70001 rows need a wide index");
        };
        assert!(rows
            .iter()
            .zip(&index)
            .all(|(r, &i)| distinct[i as usize] == *r));
    }
}
