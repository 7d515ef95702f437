//! The one way a range of a map (`speed: (1.1, 1.5)`, `delay`, ...) is drawn from: uniform
//! between its ends, from the world's seeded ChaCha8 streams (docs/ARCHITECTURE.md §2).

use rand::RngExt;
use rand_chacha::ChaCha8Rng;

/// A draw uniform in `[lo, hi)`, or `lo` when the range is a point (`hi <= lo`).
pub(crate) fn uniform(rng: &mut ChaCha8Rng, (lo, hi): (f64, f64)) -> f64 {
    if hi > lo {
        lo + rng.random_range(0.0..1.0) * (hi - lo)
    } else {
        lo
    }
}
