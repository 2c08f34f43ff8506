//! The radial fan of an edge, kept small: up to two faces in the edge record itself,
//! longer fans (fins) in a pool owned by the store.
//!
//! Why not a `SmallVec<[FaceKey; 2]>`: its capacity word makes it 24 bytes and 8-byte
//! aligned, so an edge record took 40 bytes in its slot. [`Fan`] is 20 bytes with 4-byte
//! alignment, and an edge then fills exactly 32 bytes, two to a cache line; the
//! contraction loop reads the fans of every edge around both ends of each pair, and
//! each edge read is a cache miss the first time. Fans longer than two are rare (a
//! manifold edge never has one), so the extra indirection of the pool is rarely paid.

use super::FaceKey;

/// Fans of up to this many faces live in the edge record.
const INLINE: usize = 2;

/// The faces of one edge, each once, in insertion order (appends go last, removals keep
/// the order of the rest). Read and changed through the store's [`FanPool`].
#[derive(Clone, Debug)]
pub(super) enum Fan {
    /// Up to [`INLINE`] faces: the first `len` of `faces` (the rest are filler).
    Inline {
        /// How many of `faces` are in the fan.
        len: u8,
        /// The faces, then filler.
        faces: [FaceKey; INLINE],
    },
    /// More than [`INLINE`] faces: the list at this index of the pool.
    Pooled(u32),
}

impl Default for Fan {
    /// The empty fan.
    fn default() -> Self {
        Fan::Inline {
            len: 0,
            faces: [FaceKey::default(); INLINE],
        }
    }
}

/// The lists of the fans that outgrew their edge record, with a free list so that the
/// contraction loop reuses them instead of allocating.
#[derive(Clone, Debug, Default)]
pub(super) struct FanPool {
    lists: Vec<Vec<FaceKey>>,
    /// Indices of `lists` no fan uses (their vectors are empty, capacity kept).
    free: Vec<u32>,
}

impl FanPool {
    /// The faces of `fan`.
    #[inline]
    pub(super) fn get<'a>(&'a self, fan: &'a Fan) -> &'a [FaceKey] {
        match fan {
            Fan::Inline { len, faces } => &faces[..usize::from(*len)],
            Fan::Pooled(i) => &self.lists[*i as usize],
        }
    }

    /// A fan of `faces`, in that order.
    pub(super) fn make(&mut self, faces: impl ExactSizeIterator<Item = FaceKey>) -> Fan {
        if faces.len() <= INLINE {
            let mut fan = Fan::default();
            for f in faces {
                self.push(&mut fan, f);
            }
            fan
        } else {
            let i = self.allocate();
            self.lists[i as usize].extend(faces);
            Fan::Pooled(i)
        }
    }

    /// Appends `f` to `fan`.
    #[inline]
    pub(super) fn push(&mut self, fan: &mut Fan, f: FaceKey) {
        match fan {
            Fan::Inline { len, faces } if usize::from(*len) < INLINE => {
                faces[usize::from(*len)] = f;
                *len += 1;
            }
            Fan::Inline { faces, .. } => {
                let i = self.allocate();
                let list = &mut self.lists[i as usize];
                list.extend_from_slice(faces);
                list.push(f);
                *fan = Fan::Pooled(i);
            }
            Fan::Pooled(i) => self.lists[*i as usize].push(f),
        }
    }

    /// Removes the first occurrence of `f` from `fan`, keeping the order of the rest;
    /// returns whether it was there. A pooled fan that shrinks to [`INLINE`] faces moves
    /// back into the edge record and frees its list.
    #[inline]
    pub(super) fn remove(&mut self, fan: &mut Fan, f: FaceKey) -> bool {
        match fan {
            // Spelled out for two: this runs three times per removed face.
            Fan::Inline { len, faces } => match *len {
                1 | 2 if faces[0] == f => {
                    faces[0] = faces[1];
                    *len -= 1;
                    true
                }
                2 if faces[1] == f => {
                    *len = 1;
                    true
                }
                _ => false,
            },
            Fan::Pooled(i) => {
                let index = *i;
                let list = &mut self.lists[index as usize];
                let Some(at) = list.iter().position(|&x| x == f) else {
                    return false;
                };
                list.remove(at);
                if list.len() <= INLINE {
                    let mut faces = [FaceKey::default(); INLINE];
                    faces[..list.len()].copy_from_slice(list);
                    *fan = Fan::Inline {
                        len: list.len() as u8,
                        faces,
                    };
                    self.release(index);
                }
                true
            }
        }
    }

    /// Appends the faces of `fan` to `out` and empties `fan`.
    #[inline]
    pub(super) fn take(&mut self, fan: &mut Fan, out: &mut Vec<FaceKey>) {
        out.extend_from_slice(self.get(fan));
        if let Fan::Pooled(i) = *fan {
            self.release(i);
        }
        *fan = Fan::default();
    }

    /// Empties `fan` (for a fan whose edge is removed with it).
    pub(super) fn clear(&mut self, fan: &mut Fan) {
        if let Fan::Pooled(i) = *fan {
            self.release(i);
        }
        *fan = Fan::default();
    }

    /// An empty list's index, reused if one is free.
    fn allocate(&mut self) -> u32 {
        self.free.pop().unwrap_or_else(|| {
            self.lists.push(Vec::new());
            (self.lists.len() - 1) as u32
        })
    }

    /// Returns list `i` to the free list, emptied.
    fn release(&mut self, i: u32) {
        self.lists[i as usize].clear();
        self.free.push(i);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use slotmap::KeyData;

    fn key(i: u32) -> FaceKey {
        KeyData::from_ffi(1 << 32 | u64::from(i)).into()
    }

    #[test]
    fn a_fan_is_twenty_bytes_and_four_aligned() {
        assert_eq!(std::mem::size_of::<Fan>(), 20);
        assert_eq!(std::mem::align_of::<Fan>(), 4);
    }

    #[test]
    fn grows_into_the_pool_and_back_keeping_order() {
        let mut pool = FanPool::default();
        let mut fan = Fan::default();
        assert!(pool.get(&fan).is_empty());
        for i in 1..=4 {
            pool.push(&mut fan, key(i));
        }
        assert!(matches!(fan, Fan::Pooled(0)));
        assert_eq!(pool.get(&fan), &[key(1), key(2), key(3), key(4)]);
        assert!(pool.remove(&mut fan, key(2)));
        assert!(!pool.remove(&mut fan, key(2)));
        assert_eq!(pool.get(&fan), &[key(1), key(3), key(4)]);
        assert!(pool.remove(&mut fan, key(1)));
        assert!(matches!(fan, Fan::Inline { len: 2, .. }));
        assert_eq!(pool.get(&fan), &[key(3), key(4)]);
        assert_eq!(pool.free, vec![0]);
        assert!(pool.remove(&mut fan, key(3)));
        assert_eq!(pool.get(&fan), &[key(4)]);
        assert!(!pool.remove(&mut fan, key(9)));
    }

    #[test]
    fn take_make_and_clear_reuse_freed_lists() {
        let mut pool = FanPool::default();
        let mut big = pool.make([1, 2, 3].map(key).into_iter());
        let mut small = pool.make([5].map(key).into_iter());
        assert!(matches!(big, Fan::Pooled(0)));
        assert!(matches!(small, Fan::Inline { len: 1, .. }));
        let mut out = vec![key(9)];
        pool.take(&mut big, &mut out);
        assert_eq!(out, [9, 1, 2, 3].map(key));
        assert!(pool.get(&big).is_empty());
        for i in 6..=7 {
            pool.push(&mut small, key(i));
        }
        // The list freed by `take` is reused rather than a new one allocated.
        assert!(matches!(small, Fan::Pooled(0)));
        assert_eq!(pool.lists.len(), 1);
        pool.clear(&mut small);
        assert!(pool.get(&small).is_empty());
        assert_eq!(pool.free, vec![0]);
    }
}
