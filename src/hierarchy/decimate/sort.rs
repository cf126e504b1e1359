//! The decimation's parallel sorts: stable counting and radix sorts whose result is the same for
//! any number of threads (each block or chunk counts, then places, its own entries).

use rayon::prelude::*;

/// A stable counting sort of `items` by a 15-bit `digit`: `place(slot, item)` is called once per
/// item with its place in the sorted order. In parallel (when `parallel`) over one chunk of
/// consecutive items per thread: each chunk counts its digits, the counts give each chunk its
/// first place per digit (digits in order, chunks in order within a digit), and each chunk
/// places its items, so the order is the same for any number of chunks. (Unlike `bucket_sort`,
/// whose blocks each read every item: on random keys half of a block's branches mispredict.)
pub(super) fn digit_sort<T: Sync>(
    items: &[T],
    digit: impl Fn(&T) -> usize + Sync,
    parallel: bool,
    place: impl Fn(usize, &T) + Sync,
) {
    const DIGITS: usize = 1 << 15;
    let chunks = if parallel {
        rayon::current_num_threads().clamp(1, MAX_BLOCKS)
    } else {
        1
    };
    let chunk_len = items.len().div_ceil(chunks).max(1);
    let mut next: Vec<Vec<u32>> = items
        .par_chunks(chunk_len)
        .map(|chunk| {
            let mut count = vec![0u32; DIGITS];
            for item in chunk {
                count[digit(item)] += 1;
            }
            count
        })
        .collect();
    let mut sum = 0;
    for d in 0..DIGITS {
        for count in &mut next {
            (count[d], sum) = (sum, sum + count[d]);
        }
    }
    items
        .par_chunks(chunk_len)
        .zip(next)
        .for_each(|(chunk, mut next)| {
            for item in chunk {
                let slot = &mut next[digit(item)];
                place(*slot as usize, item);
                *slot += 1;
            }
        });
}

/// `items` sorted by their first value, stably (a least-significant-digit radix sort, three
/// digits of 11 bits); `spare` is scratch space.
pub(super) fn sort_by_first(items: &mut Vec<[u32; 2]>, spare: &mut Vec<[u32; 2]>) {
    const BITS: u32 = 11;
    const BUCKETS: usize = 1 << BITS;
    let digit = |key: u32, d: u32| (key >> (d * BITS)) as usize & (BUCKETS - 1);
    let mut counts = [[0u32; BUCKETS]; 3];
    for &[key, _] in items.iter() {
        for (d, count) in counts.iter_mut().enumerate() {
            count[digit(key, d as u32)] += 1;
        }
    }
    spare.clear();
    spare.resize(items.len(), [0; 2]);
    for (d, count) in counts.iter_mut().enumerate() {
        if count.iter().any(|&c| c as usize == items.len()) {
            continue;
        }
        let mut sum = 0;
        for c in count.iter_mut() {
            (*c, sum) = (sum, sum + *c);
        }
        for &item in items.iter() {
            let slot = &mut count[digit(item[0], d as u32)];
            spare[*slot as usize] = item;
            *slot += 1;
        }
        std::mem::swap(items, spare);
    }
}

/// Where [`bucket_sort`] writes: the values bucket by bucket, where each bucket starts, and
/// scratch space.
pub(super) struct SortedBuckets<'a, T> {
    pub offsets: &'a mut Vec<u32>,
    pub cursor: &'a mut Vec<u32>,
    pub sorted: &'a mut Vec<T>,
}

/// A stable counting sort: item `i` of `0..items` brings the `K` entries `entries(i)`, each a
/// bucket in `0..buckets` and a value; `sorted` gets the values bucket by bucket, in item order
/// within a bucket, and `offsets` (`buckets + 1` of them) where each bucket starts. `cursor` is
/// scratch space.
///
/// In parallel: one block of consecutive buckets per thread. Each block reads every item and
/// counts, then places, only the entries that fall in it, so the result is the same for any
/// number of blocks. (Reading the items once per block costs little next to the scattered
/// writes, which are what the blocks share out.)
pub(super) fn bucket_sort<T: Copy + Default + Send + Sync, const K: usize>(
    items: usize,
    buckets: usize,
    parallel: bool,
    entries: impl Fn(usize) -> [(u32, T); K] + Sync,
    out: SortedBuckets<T>,
) {
    let SortedBuckets {
        offsets,
        cursor,
        sorted,
    } = out;
    let blocks = if parallel {
        rayon::current_num_threads().clamp(1, MAX_BLOCKS)
    } else {
        1
    };
    let block_len = buckets.div_ceil(blocks).max(1);
    offsets.clear();
    offsets.resize(buckets + 1, 0);
    // Each block's counts, then their running sums within the block.
    offsets[1..]
        .par_chunks_mut(block_len)
        .enumerate()
        .for_each(|(b, ends)| {
            let (first, len) = ((b * block_len) as u32, ends.len() as u32);
            for i in 0..items {
                for (bucket, _) in entries(i) {
                    let j = bucket.wrapping_sub(first);
                    if j < len {
                        ends[j as usize] += 1;
                    }
                }
            }
            for j in 1..ends.len() {
                ends[j] += ends[j - 1];
            }
        });
    // Then each block's start added to its entries.
    let block_entries: Vec<u32> = offsets[1..]
        .chunks(block_len)
        .map(|ends| ends.last().copied().unwrap_or(0))
        .collect();
    let block_start = running_starts(&block_entries);
    offsets[1..]
        .par_chunks_mut(block_len)
        .zip(&block_start)
        .for_each(|(ends, &start)| ends.iter_mut().for_each(|e| *e += start));
    // Fresh zeroed pages from the allocator: the blocks' writes fault them in, in parallel.
    *sorted = vec![T::default(); K * items];
    cursor.clear();
    cursor.extend_from_slice(&offsets[..buckets]);
    let sorted_of_block = split_by_lengths(sorted, &block_entries);
    cursor
        .par_chunks_mut(block_len)
        .zip(sorted_of_block)
        .enumerate()
        .for_each(|(b, (cursor, sorted))| {
            let (first, len) = ((b * block_len) as u32, cursor.len() as u32);
            let base = block_start[b];
            for i in 0..items {
                for (bucket, value) in entries(i) {
                    let j = bucket.wrapping_sub(first);
                    if j < len {
                        let slot = &mut cursor[j as usize];
                        sorted[(*slot - base) as usize] = value;
                        *slot += 1;
                    }
                }
            }
        });
}

/// At most this many blocks of [`bucket_sort`] (each reads every item).
pub(super) const MAX_BLOCKS: usize = 16;

/// Where each chunk's items start, for chunks of `lengths` items.
pub(super) fn running_starts(lengths: &[u32]) -> Vec<u32> {
    lengths
        .iter()
        .scan(0u32, |sum, &len| {
            let start = *sum;
            *sum += len;
            Some(start)
        })
        .collect()
}

/// `items` cut into consecutive pieces of `lengths` items (which add up to at most its length).
pub(super) fn split_by_lengths<'a, T>(mut items: &'a mut [T], lengths: &[u32]) -> Vec<&'a mut [T]> {
    lengths
        .iter()
        .map(|&len| {
            let (piece, rest) = std::mem::take(&mut items).split_at_mut(len as usize);
            items = rest;
            piece
        })
        .collect()
}
