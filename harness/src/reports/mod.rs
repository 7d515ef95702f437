//! What runs leave behind: result files written atomically ([`files`]), SVG figures
//! ([`figures`]) and an episode's self-contained HTML replay page ([`replay_page`]).

pub mod figures;
pub mod files;
pub mod replay_page;
