//! The logs that let [`Rule::try_integrate`](super::Rule::try_integrate)
//! take an integral again, rescaled, without spending its budget twice.
//!
//! A pass of an integral whose values exceed `2^500` (sums overflow) or lie
//! below `2^-500` (squares underflow) is taken again of `f 2^-e`. Evaluating
//! `f` again spent the budget twice (stratified sampling made 510 evaluations
//! at a budget of 255 on a Gaussian peak of width 1e-4 that no sample
//! reached; G7–K15 90 at 45). A budget is a promise, so every pass logs what
//! it drew and what it saw, and the next pass replays it:
//!
//! * [`LoggedRng`] hands back the logged words of the caller's generator in
//!   order, so a random rule places the same points, and draws (and logs)
//!   afresh from the first request the log does not answer;
//! * a [`Log`] of points and values gives back the value while the rule asks
//!   for the logged points in order; from the first point that differs (an
//!   adaptive rule, whose decisions on the scaled values differ) the caller
//!   evaluates, counted, and the log continues from there.
//!
//! Each log holds at most [`LOG_BYTES`], so memory stays bounded (a rule
//! that draws nothing leaves its log of draws empty); a pass
//! beyond that evaluates again, counted, within the budget.

use std::convert::Infallible;

use smallvec::SmallVec;

/// The most memory one log of an integral holds, in bytes (1 MiB: 65536
/// one-dimensional real evaluations, 26214 two-dimensional RGB ones; a pass
/// stopped at the first value beyond `2^500` has mostly logged far fewer).
pub const LOG_BYTES: usize = 1 << 20;

/// Items a [`Log`] holds in place, before it allocates: a few-node
/// integral (Gauss–Legendre at n = 10 with its estimate logs 27 points)
/// allocates nothing; its allocation and release were some 350 of the
/// 2900 instructions of a call at n = 5 (callgrind).
const INLINE: usize = 32;

/// What the passes of an integral have seen or drawn, in order, with a
/// cursor for the pass under way.
pub struct Log<T> {
    items: SmallVec<[T; INLINE]>,
    cap: usize,
    cursor: usize,
}

impl<T: Copy> Log<T> {
    /// An empty log (it allocates as it grows, never past its cap).
    pub fn new() -> Self {
        Log {
            items: SmallVec::new(),
            cap: LOG_BYTES / std::mem::size_of::<T>().max(1),
            cursor: 0,
        }
    }

    /// Starts a pass: the next [`Log::replay`] reads the first item.
    pub fn rewind(&mut self) {
        self.cursor = 0;
    }

    /// The item at the cursor when `same` accepts it (and the cursor moves
    /// on); otherwise `None`, and the log is cut at the cursor: what follows
    /// belonged to another path.
    #[inline]
    pub fn replay(&mut self, same: impl Fn(&T) -> bool) -> Option<T> {
        match self.items.get(self.cursor) {
            Some(item) if same(item) => {
                self.cursor += 1;
                Some(*item)
            }
            Some(_) => {
                self.items.truncate(self.cursor);
                None
            }
            None => None,
        }
    }

    /// Makes room for `n` items at once, never past the cap.
    pub fn reserve(&mut self, n: u64) {
        let room = n.min((self.cap - self.items.len()) as u64) as usize;
        self.items.reserve_exact(room);
    }

    /// Logs a fresh item at the end, within the [`Log::reserve`]d room, during
    /// a first pass (which replays nothing and leaves the cursor to
    /// [`Log::rewind`]): a bounds check and a store. True when it was logged.
    #[inline(always)]
    pub fn push(&mut self, item: T) -> bool {
        if self.items.len() < self.items.capacity().min(self.cap) {
            self.items.push(item);
            true
        } else {
            false
        }
    }

    /// The number of items logged.
    pub fn len(&self) -> usize {
        self.items.len()
    }

    /// Folds `f` over every item logged.
    pub fn fold<A>(&self, init: A, f: impl FnMut(A, &T) -> A) -> A {
        self.items.iter().fold(init, f)
    }

    /// Logs a fresh item at the cursor (the end of the log after a
    /// [`Log::replay`] of `None`), while the log is within its cap; true when
    /// it was logged.
    #[inline]
    pub fn append(&mut self, item: T) -> bool {
        let len = self.items.len();
        if self.cursor == len && len < self.cap {
            if len == self.items.capacity() {
                self.grow();
            }
            self.items.push(item);
            self.cursor += 1;
            true
        } else {
            false
        }
    }

    /// Room for more items: doubling, never past the cap.
    #[cold]
    fn grow(&mut self) {
        let len = self.items.len();
        self.items.reserve_exact(len.max(64).min(self.cap - len));
    }

    /// Logs `item` at the end of a full log, growing it while within the cap
    /// (a first pass's draws, past the room reserved for them).
    #[cold]
    fn grow_with(&mut self, item: T) {
        if self.items.len() < self.cap {
            self.grow();
            self.items.push(item);
        }
    }

    /// Logs nothing more: a draw that cannot be replayed (bytes) ends it.
    pub fn close(&mut self) {
        self.items.truncate(self.cursor);
        self.cap = self.items.len();
    }
}

/// The bit patterns of a point: a replayed point is the logged one exactly.
#[inline]
pub fn bits<const D: usize>(u: [f64; D]) -> [u64; D] {
    u.map(f64::to_bits)
}

/// One draw from a generator, as the rule asked for it.
#[derive(Clone, Copy)]
pub enum Draw {
    /// A `next_u32`.
    U32(u32),
    /// A `next_u64`.
    U64(u64),
}

/// The caller's generator seen through a [`Log`] of its draws: logged words
/// are handed back in order, the rest drawn and logged.
pub struct LoggedRng<'a, R: ?Sized> {
    /// The caller's generator.
    pub inner: &'a mut R,
    /// The draws of the passes so far.
    pub log: &'a mut Log<Draw>,
    /// False in a first pass: nothing to replay, every draw is fresh.
    pub replaying: bool,
}

impl<R: rand::Rng + ?Sized> LoggedRng<'_, R> {
    /// The next word of the kind `same` accepts: the logged one while
    /// replaying and the log agrees, else a fresh one drawn by `fresh` and
    /// logged.
    #[inline(always)]
    fn draw(&mut self, same: fn(&Draw) -> bool, fresh: impl FnOnce(&mut R) -> Draw) -> Draw {
        if self.replaying
            && let Some(d) = self.log.replay(same)
        {
            return d;
        }
        let d = fresh(self.inner);
        self.fresh(d);
        d
    }

    /// A fresh draw, logged: in a first pass at the end of the log, else at
    /// the cursor where the replay ended.
    #[inline(always)]
    fn fresh(&mut self, draw: Draw) {
        if self.replaying {
            let _ = self.log.append(draw);
        } else if self.log.items.len() < self.log.items.capacity().min(self.log.cap) {
            self.log.items.push(draw);
        } else {
            self.log.grow_with(draw);
        }
    }
}

impl<R: rand::Rng + ?Sized> rand::TryRng for LoggedRng<'_, R> {
    type Error = Infallible;

    fn try_next_u32(&mut self) -> Result<u32, Infallible> {
        let word = self.draw(|d| matches!(d, Draw::U32(_)), |r| Draw::U32(r.next_u32()));
        Ok(match word {
            Draw::U32(x) => x,
            Draw::U64(x) => x as u32,
        })
    }

    fn try_next_u64(&mut self) -> Result<u64, Infallible> {
        let word = self.draw(|d| matches!(d, Draw::U64(_)), |r| Draw::U64(r.next_u64()));
        Ok(match word {
            Draw::U64(x) => x,
            Draw::U32(x) => u64::from(x),
        })
    }

    fn try_fill_bytes(&mut self, dst: &mut [u8]) -> Result<(), Infallible> {
        // No rule here draws bytes; one that does is not replayed from here.
        self.log.close();
        self.inner.fill_bytes(dst);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    /// A log of large entries fills to its cap without a panic (the growth
    /// step was `clamp(64, cap - len)`, which panics when `cap - len < 64`)
    /// and then logs nothing more.
    #[test]
    fn a_log_of_large_entries_fills_to_its_cap() {
        let mut log = Log::<[u8; 600]>::new();
        let cap = LOG_BYTES / 600;
        let logged = (0..cap + 10).filter(|_| log.append([0; 600])).count();
        assert_eq!(logged, cap);
    }

    /// A second pass reads the first pass's draws back, and a pass that asks
    /// for something else draws afresh from the caller's generator.
    #[test]
    fn a_replayed_generator_gives_the_same_words_then_fresh_ones() {
        let mut rng = rand_pcg::Pcg64::seed_from_u64(1);
        let mut log = Log::new();
        let first: Vec<u64> = {
            let mut r = LoggedRng {
                inner: &mut rng,
                log: &mut log,
                replaying: true,
            };
            (0..4).map(|_| r.next_u64()).collect()
        };
        log.rewind();
        let mut r = LoggedRng {
            inner: &mut rng,
            log: &mut log,
            replaying: true,
        };
        let again: Vec<u64> = (0..4).map(|_| r.next_u64()).collect();
        assert_eq!(first, again);
        // Past the log: fresh words, not the logged ones again.
        let fresh = r.next_u64();
        assert!(!first.contains(&fresh));
        // A draw of another kind cuts the log there.
        log.rewind();
        let mut r = LoggedRng {
            inner: &mut rng,
            log: &mut log,
            replaying: true,
        };
        assert_eq!(r.next_u64(), first[0]);
        let _ = r.next_u32();
        log.rewind();
        let mut r = LoggedRng {
            inner: &mut rng,
            log: &mut log,
            replaying: true,
        };
        assert_eq!(r.next_u64(), first[0]);
        assert_ne!(r.next_u64(), first[1]);
    }
}
