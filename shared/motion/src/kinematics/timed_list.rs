//! A fixed-capacity list of timestamped events of one cycle (input edges, output edges): pushed
//! on the cyclic path without allocating; what does not fit is counted, not lost silently.

/// An event with a time (ns, cell clock).
pub trait Timed {
    /// Time of the event (ns).
    fn time_ns(&self) -> i64;
}

/// Up to `N` events; the excess is counted in [`TimedList::dropped`].
#[derive(Copy, Clone, Debug)]
pub struct TimedList<T, const N: usize> {
    buf: [T; N],
    len: usize,
    /// Events dropped because the list was full.
    pub(crate) dropped: u64,
}

impl<T: Copy + Default, const N: usize> Default for TimedList<T, N> {
    fn default() -> Self {
        Self {
            buf: [T::default(); N],
            len: 0,
            dropped: 0,
        }
    }
}

impl<T: Copy, const N: usize> TimedList<T, N> {
    /// Appends an event; when full the event is dropped and counted.
    pub fn push(&mut self, e: T) {
        if let Some(slot) = self.buf.get_mut(self.len) {
            *slot = e;
            self.len += 1;
        } else {
            self.dropped += 1;
        }
    }

    /// The events.
    pub fn as_slice(&self) -> &[T] {
        &self.buf[..self.len.min(N)]
    }

    /// Removes all events (the dropped count stays).
    pub fn clear(&mut self) {
        self.len = 0;
    }

    /// Number of events.
    pub fn len(&self) -> usize {
        self.len
    }

    /// No events.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Events dropped because the list was full (since creation).
    pub fn dropped(&self) -> u64 {
        self.dropped
    }
}

impl<T: Copy + Timed, const N: usize> TimedList<T, N> {
    /// Stable sort by time (insertion sort: no allocation, `N` is small).
    pub(crate) fn sort(&mut self) {
        let n = self.len.min(N);
        for i in 1..n {
            let mut j = i;
            while j > 0 && self.buf[j - 1].time_ns() > self.buf[j].time_ns() {
                self.buf.swap(j - 1, j);
                j -= 1;
            }
        }
    }
}
