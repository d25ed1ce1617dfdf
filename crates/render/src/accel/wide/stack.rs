//! The traversal stack: uninitialised storage, entries ordered by entry distance.

use std::mem::MaybeUninit;

/// Traversal stack entries for any tree: the binary tree is at most 64 levels deep, the wide
/// tree made from it no deeper, and each level leaves at most seven siblings on the stack.
/// (The stack is not initialised, so its size costs nothing per ray.)
pub(super) const STACK_SIZE: usize = 7 * 64 + 8;
/// A stack of at most `N` entries whose storage is left uninitialised until pushed to, so
/// that setting one up for every ray costs nothing. Pushing past `N` panics.
pub(super) struct Stack<T: Copy, const N: usize> {
    items: [MaybeUninit<T>; N],
    /// Entries `items[..len]` have been written.
    len: usize,
}

impl<T: Copy + Ord, const N: usize> Stack<T, N> {
    #[inline(always)]
    pub(super) fn new() -> Self {
        Stack {
            items: [const { MaybeUninit::uninit() }; N],
            len: 0,
        }
    }

    #[inline(always)]
    pub(super) fn len(&self) -> usize {
        self.len
    }

    #[inline(always)]
    pub(super) fn push(&mut self, item: T) {
        self.items[self.len].write(item);
        self.len += 1;
    }

    #[inline(always)]
    pub(super) fn pop(&mut self) -> Option<T> {
        if self.len == 0 {
            return None;
        }
        self.len -= 1;
        // SAFETY: `items[..len]` were written (invariant), and `len` was above this index.
        Some(unsafe { self.items[self.len].assume_init() })
    }

    /// Sorts the entries from `base` to the top, largest deepest, by insertion (few entries).
    #[inline(always)]
    pub(super) fn sort_descending_from(&mut self, base: usize) {
        // SAFETY: every index read is below `len`, so written (invariant).
        let at = |items: &[MaybeUninit<T>; N], i: usize| unsafe { items[i].assume_init() };
        for i in base + 1..self.len {
            let e = at(&self.items, i);
            let mut j = i;
            while j > base && at(&self.items, j - 1) < e {
                let moved = at(&self.items, j - 1);
                self.items[j].write(moved);
                j -= 1;
            }
            self.items[j].write(e);
        }
    }
}

/// A traversal stack entry: a child's entry distance (high half) and word (low half). Entry
/// distances are non-negative, so entries order as their distances do.
#[inline(always)]
pub(super) fn stack_entry(word: u32, t: f32) -> u64 {
    (u64::from(t.to_bits()) << 32) | u64::from(word)
}

/// `(min, max)` of two stack entries, without branches.
#[inline(always)]
pub(super) fn order(a: u64, b: u64) -> (u64, u64) {
    (a.min(b), a.max(b))
}
