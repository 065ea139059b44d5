//! The LOD scene's layout: a grid of instances of one mesh, the levels' face fractions, and
//! which level an instance draws for its size on screen.

/// The LOD scene: a grid of instances, as in the seed that measured 13.5 → 26.5 FPS.
pub const LOD_GRID: usize = 21;
/// Fractions of the faces kept by levels 1, 2, 3 (level 0 is the original).
pub const LOD_RATIOS: [f64; 3] = [0.25, 0.06, 0.015];

/// Instances this many diagonals apart.
pub(super) const LOD_SPACING: f32 = 1.25;

/// The level an instance `pixels` tall on screen draws, of levels keeping `fractions` of the
/// original's faces (the original first, 1): the finest whose faces per square pixel stay
/// within the original's at [`LOD_FULL_PIXELS`] tall, else the coarsest. Levels 4× apart in
/// faces change at each halving of the size.
pub fn lod_level(pixels: f32, fractions: &[f64]) -> usize {
    let budget = (pixels as f64 / LOD_FULL_PIXELS as f64).powi(2);
    fractions
        .iter()
        .position(|&f| f <= budget)
        .unwrap_or(fractions.len().saturating_sub(1))
}

/// On-screen height from which the LOD scene draws the original.
pub const LOD_FULL_PIXELS: f32 = 240.0;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn larger_instances_draw_finer_levels() {
        let levels = [1.0, 0.25, 0.0625, 0.015625];
        assert_eq!(lod_level(1e4, &levels), 0, "large on screen: the original");
        let mut last = 0;
        for px in [500.0, 240.0, 200.0, 100.0, 50.0, 20.0, 1.0, 0.0] {
            let l = lod_level(px, &levels);
            assert!(l >= last && l < levels.len(), "{px} px: level {l}");
            last = l;
        }
        assert_eq!(last, levels.len() - 1, "tiny is the coarsest");
        assert_eq!(lod_level(0.0, &[1.0]), 0, "one level only");
        // 4x apart in faces: a level per halving of the size.
        for (px, level) in [(241.0, 0), (239.0, 1), (121.0, 1), (119.0, 2), (59.0, 3)] {
            assert_eq!(lod_level(px, &levels), level, "{px} px");
        }
        // Levels of a lods run (0.5 .. 0.01): each its own size band, in order.
        let run = [1.0, 0.5, 0.25, 0.1, 0.05, 0.01];
        let bands: Vec<usize> = [240.0, 200.0, 150.0, 100.0, 60.0, 30.0, 10.0]
            .iter()
            .map(|&px| lod_level(px, &run))
            .collect();
        assert_eq!(bands, [0, 1, 2, 3, 4, 5, 5]);
    }
}
