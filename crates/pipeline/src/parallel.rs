//! Parallel matching of scan pairs, with each scan prepared once.
//!
//! Pairs come as a chain — (0, k), (k, 2k), … — so the second scan of a pair is the
//! first scan of the next. The pairs are cut into contiguous chunks (of
//! [`CHUNK_PAIRS`], smaller when there are few pairs: [`chunk_pairs`]); a worker walks a
//! chunk in order, keeping the last prepared scan to reuse it as the next reference,
//! so a scan is prepared once (twice at chunk boundaries). Each worker owns one
//! matcher (scratch buffers). Every result depends only on its two scans, and results
//! come back in pair order, so the output is the same whatever the thread count.

use rayon::prelude::*;

/// Pairs per chunk at most: large enough that preparing the boundary scan twice is
/// rare, small enough to balance the load over the threads.
pub const CHUNK_PAIRS: usize = 64;

/// Chunks per thread at least, when there are few pairs: a few hundred pairs (the
/// bootstrap's) or a few dozen (the closure check's) in chunks of [`CHUNK_PAIRS`]
/// would leave threads idle (60 pairs: one chunk, one thread), and the last chunk
/// matched alone is the time one thread waits for the other at the end.
pub const CHUNKS_PER_THREAD: usize = 16;

/// Pairs per chunk at least: a chunk of a chain prepares one scan more than it has
/// pairs.
pub const MIN_CHUNK_PAIRS: usize = 4;

/// Pairs per chunk for `pairs` pairs on `threads` threads: [`CHUNK_PAIRS`], or fewer
/// (down to [`MIN_CHUNK_PAIRS`]) so that every thread gets [`CHUNKS_PER_THREAD`]
/// chunks.
pub fn chunk_pairs(pairs: usize, threads: usize) -> usize {
    (pairs / (CHUNKS_PER_THREAD * threads.max(1))).clamp(MIN_CHUNK_PAIRS, CHUNK_PAIRS)
}

/// Matches every pair `(first, second)` (scan indices) in parallel.
///
/// - `prepare(i)` preprocesses scan `i` (done once per scan per chunk);
/// - `new_matcher()` makes one matcher per worker;
/// - `match_pair(matcher, pair_index, &reference, &current)` matches one pair;
/// - `done()` is called once per pair matched (progress reporting).
///
/// Returns one result per pair, in the order of `pairs`.
pub fn match_chain<P, M, R>(
    pairs: &[(usize, usize)],
    prepare: impl Fn(usize) -> P + Sync + Send,
    new_matcher: impl Fn() -> M + Sync + Send,
    match_pair: impl Fn(&mut M, usize, &P, &P) -> R + Sync + Send,
    done: impl Fn() + Sync + Send,
) -> Vec<R>
where
    R: Send,
{
    let size = chunk_pairs(pairs.len(), rayon::current_num_threads());
    let chunks: Vec<Vec<R>> = pairs
        .par_chunks(size)
        .enumerate()
        .map_init(new_matcher, |matcher, (c, chunk)| {
            let mut out = Vec::with_capacity(chunk.len());
            let mut last: Option<(usize, P)> = None;
            for (k, &(a, b)) in chunk.iter().enumerate() {
                let reference = match last.take() {
                    Some((i, p)) if i == a => p,
                    _ => prepare(a),
                };
                let current = prepare(b);
                out.push(match_pair(matcher, c * size + k, &reference, &current));
                last = Some((b, current));
                done();
            }
            out
        })
        .collect();
    chunks.into_iter().flatten().collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::{AtomicUsize, Ordering};

    #[test]
    fn results_in_order_and_scans_prepared_about_once() {
        let pairs: Vec<(usize, usize)> = (0..1000).map(|i| (3 * i, 3 * i + 3)).collect();
        let prepared = AtomicUsize::new(0);
        let done = AtomicUsize::new(0);
        let run = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| {
                match_chain(
                    &pairs,
                    |i| {
                        prepared.fetch_add(1, Ordering::Relaxed);
                        i as f64 * 0.5
                    },
                    || 0usize,
                    |calls: &mut usize, k, a: &f64, b: &f64| {
                        *calls += 1;
                        (k, *a, *b)
                    },
                    || {
                        done.fetch_add(1, Ordering::Relaxed);
                    },
                )
            })
        };
        let one = run(1);
        // One scan more per chunk than it has pairs.
        let chunks = 1000_usize.div_ceil(chunk_pairs(1000, 1));
        assert_eq!(prepared.swap(0, Ordering::Relaxed), 1000 + chunks);
        let two = run(2);
        assert_eq!(one, two);
        assert_eq!(done.load(Ordering::Relaxed), 2000);
        for (k, r) in one.iter().enumerate() {
            assert_eq!(*r, (k, 1.5 * k as f64, 1.5 * (k + 1) as f64));
        }
    }

    #[test]
    fn few_pairs_are_cut_into_chunks_for_every_thread_and_keep_their_index() {
        assert_eq!(chunk_pairs(60, 2), MIN_CHUNK_PAIRS);
        assert_eq!(chunk_pairs(300, 2), 9);
        assert_eq!(chunk_pairs(1200, 2), 37);
        assert_eq!(chunk_pairs(4000, 2), CHUNK_PAIRS);
        assert_eq!(chunk_pairs(0, 2), MIN_CHUNK_PAIRS);
        assert_eq!(chunk_pairs(5, 0), MIN_CHUNK_PAIRS);
        let pairs: Vec<(usize, usize)> = (0..61).map(|i| (2 * i, 2 * i + 2)).collect();
        let run = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| {
                match_chain(
                    &pairs,
                    |i| i,
                    || (),
                    |_, k, a: &usize, b: &usize| (k, *a, *b),
                    || {},
                )
            })
        };
        let one = run(1);
        for (k, r) in one.iter().enumerate() {
            assert_eq!(*r, (k, pairs[k].0, pairs[k].1));
        }
        assert_eq!(run(2), one);
        assert_eq!(run(3), one);
    }

    #[test]
    fn broken_chain_prepares_both_scans() {
        let pairs = vec![(0, 2), (4, 6), (6, 8)];
        let prepared = AtomicUsize::new(0);
        let r = match_chain(
            &pairs,
            |i| {
                prepared.fetch_add(1, Ordering::Relaxed);
                i
            },
            || (),
            |_, _, a: &usize, b: &usize| (*a, *b),
            || {},
        );
        assert_eq!(r, pairs);
        assert_eq!(prepared.load(Ordering::Relaxed), 5);
    }
}
