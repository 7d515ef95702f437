//! The space-filling first stage: points of an Owen-scrambled Sobol sequence
//! ([`sobol_burley`], Burley 2020, "Practical Hash-based Owen Scrambling"), one
//! coordinate in [0, 1) per parameter. Scrambling makes every point uniform on the unit
//! cube, so the share of stage-one candidates that fail is an unbiased estimate of the
//! failure probability over the space, while the points fill the cube more evenly than
//! independent draws. The scramble seed derives from the run seed: the same seed gives
//! the same points.

use unforeseen_env::seeds::episode_seed;

/// Most points one sequence gives (the crate's limit, 2^16).
pub const MAX_POINTS: usize = 1 << 16;

/// Most coordinates a point may have (the crate's dimensions).
pub const MAX_DIMENSIONS: usize = sobol_burley::NUM_DIMENSIONS as usize;

/// Point `index` (< [`MAX_POINTS`]) of the scrambled Sobol sequence of run seed `seed`,
/// with `dims` (≤ [`MAX_DIMENSIONS`]) coordinates in [0, 1).
pub fn sobol_point(seed: u64, index: usize, dims: usize) -> Vec<f64> {
    let scramble = (episode_seed(seed, "search/sobol", 0) & 0xffff_ffff) as u32;
    let index = index.min(MAX_POINTS - 1) as u32;
    (0..dims.min(MAX_DIMENSIONS) as u32)
        .map(|d| f64::from(sobol_burley::sample(index, d, scramble)))
        .collect()
}
