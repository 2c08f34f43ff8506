//! [`SlotVec`]: data kept per element of a [`MeshStore`](super::MeshStore), in a plain
//! vector by the slot index of the element's key.

use slotmap::Key;
use std::marker::PhantomData;

/// A value per store key, at the key's slot index: what a `SecondaryMap` does, without
/// the version it keeps per entry (8 bytes with padding for a small value).
///
/// Why that is enough here: a store never reuses a slot (see
/// [`MeshStore`](super::MeshStore)), so two keys of one store never share a slot index.
/// What it gives up: a removed key still reads its old slot. Callers ask only about
/// live keys, or clear an entry when its element goes.
#[derive(Clone, Debug)]
pub(crate) struct SlotVec<K, V> {
    values: Vec<V>,
    /// What a slot holds before it is set (and what a slot beyond the end reads as).
    fill: V,
    key: PhantomData<K>,
}

/// The slot index of a key: the low half of `as_ffi`. slotmap documents `as_ffi` only
/// as a value `from_ffi` turns back into the key; that its low half is the slot index
/// (and the high half the version) is how slotmap 1.x lays it out, which the store
/// relies on too (its packed records). The test `low_halves_are_slot_indices` fails if
/// a new version lays keys out otherwise.
pub(crate) fn slot_index<K: Key>(key: K) -> usize {
    key.data().as_ffi() as u32 as usize
}

impl<K: Key, V: Clone> SlotVec<K, V> {
    /// Room for every key in `keys`, each slot holding `fill`. (Sized from the keys
    /// rather than grown: growing by doubling would hold up to twice the memory.)
    pub fn for_keys(keys: impl Iterator<Item = K>, fill: V) -> Self {
        let len = keys.map(|k| slot_index(k) + 1).max().unwrap_or(0);
        SlotVec {
            values: vec![fill.clone(); len],
            fill,
            key: PhantomData,
        }
    }

    /// The value at `key`'s slot (`fill` if it was never set).
    #[inline]
    pub fn get(&self, key: K) -> &V {
        self.values.get(slot_index(key)).unwrap_or(&self.fill)
    }

    /// The value at `key`'s slot, to change; `None` for a slot beyond the room made.
    #[inline]
    pub fn get_mut(&mut self, key: K) -> Option<&mut V> {
        self.values.get_mut(slot_index(key))
    }

    /// Sets the value at `key`'s slot, making room if needed.
    #[inline]
    pub fn set(&mut self, key: K, value: V) {
        let i = slot_index(key);
        if self.values.len() <= i {
            self.values.resize(i + 1, self.fill.clone());
        }
        self.values[i] = value;
    }

    /// Puts `fill` back at `key`'s slot and returns what was there.
    #[inline]
    pub fn take(&mut self, key: K) -> V {
        match self.values.get_mut(slot_index(key)) {
            Some(value) => std::mem::replace(value, self.fill.clone()),
            None => self.fill.clone(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use slotmap::SlotMap;

    slotmap::new_key_type! {
        struct TestKey;
    }

    /// Fresh keys' low halves are small, distinct and dense: what `SlotVec` (and the
    /// store's packed records) take them to be. Were slotmap to lay keys out
    /// otherwise, `for_keys` would size for the largest low half.
    #[test]
    fn low_halves_are_slot_indices() {
        let mut keys: SlotMap<TestKey, ()> = SlotMap::with_key();
        let n = 1000;
        let mut low: Vec<usize> = (0..n).map(|_| slot_index(keys.insert(()))).collect();
        low.sort_unstable();
        low.dedup();
        assert_eq!(low.len(), n);
        assert!(low.iter().all(|&i| i <= n), "{:?}", &low[low.len() - 3..]);
    }

    #[test]
    fn values_are_kept_per_key() {
        let mut keys: SlotMap<TestKey, ()> = SlotMap::with_key();
        let k: Vec<TestKey> = (0..3).map(|_| keys.insert(())).collect();
        let mut values = SlotVec::for_keys(k[..2].iter().copied(), 0u32);
        assert_eq!(*values.get(k[0]), 0);
        values.set(k[1], 7);
        values.set(k[2], 9); // beyond the room made: it grows
        assert_eq!((*values.get(k[1]), *values.get(k[2])), (7, 9));
        if let Some(v) = values.get_mut(k[0]) {
            *v = 5;
        }
        assert_eq!(values.take(k[0]), 5);
        assert_eq!(*values.get(k[0]), 0);
        let far = keys.insert(());
        assert_eq!(*values.get(far), 0);
        assert_eq!(values.take(far), 0);
    }
}
