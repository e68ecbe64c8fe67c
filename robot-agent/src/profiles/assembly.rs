//! A whole (an obstacle map, a snapshot of robots) sent as several chunks in one tick, put back together.

use swarm_navigation::wire::Chunk;

/// A whole (map or snapshot) assembled from chunks within one inbox.
#[derive(Debug)]
pub struct Assembly<T> {
    /// The entries received so far.
    pub items: Vec<T>,
    expected: usize,
}

impl<T> Assembly<T> {
    /// An empty whole that keeps at most `capacity` entries.
    pub fn with_capacity(capacity: usize) -> Self {
        Assembly {
            items: Vec::with_capacity(capacity),
            expected: usize::MAX,
        }
    }

    /// Takes in one chunk; returns whether the whole is complete.
    pub fn add(&mut self, chunk: &Chunk<'_>, entries: impl Iterator<Item = T>) -> bool {
        if chunk.first == 0 {
            self.items.clear();
            self.expected = usize::from(chunk.total);
        } else if usize::from(chunk.first) != self.items.len() {
            self.expected = usize::MAX;
            return false;
        }
        let room = self.items.capacity() - self.items.len();
        self.items.extend(entries.take(room));
        self.items.len() >= self.expected.min(self.items.capacity())
    }
}
