//! The GIF's fixed palette: a 6 x 6 x 6 colour cube, 39 greys evenly between black and white (four of them also
//! in the cube, which keeps the arithmetic simple) and one transparent entry for the pixels a frame leaves as the
//! frame before drew them. A fixed palette maps a pixel with a few integer operations, the same way in every
//! frame, so encoding is fast and a run always gives the same file.

/// Entries of the colour cube: levels 0, 51, ..., 255 of each channel.
const CUBE: u8 = 216;
/// Greys: levels 1 to 39 of 40 steps from black to white.
const GREYS: u8 = 39;
/// The entry of a pixel that keeps the previous frame's colour.
pub const TRANSPARENT: u8 = CUBE + GREYS;

/// The palette as a GIF stores it: red, green and blue of each of the 256 entries.
pub fn rgb_table() -> Vec<u8> {
    (0..=u8::MAX).flat_map(colour).collect()
}

/// The colour of entry `index` (black for the transparent one, which is never shown).
pub fn colour(index: u8) -> [u8; 3] {
    if index < CUBE {
        [index / 36, index / 6 % 6, index % 6].map(|level| level * 51)
    } else if index < TRANSPARENT {
        let step = u16::from(index - CUBE) + 1;
        let steps = u16::from(GREYS) + 1;
        [((step * 255 + steps / 2) / steps) as u8; 3]
    } else {
        [0; 3]
    }
}

/// The entry for `rgb`: the nearer of the nearest cube colour (each channel rounded to its level) and the grey
/// nearest the channels' mean (to within rounding: a squared distance at most 8 more than the best entry's).
pub fn nearest(rgb: [u8; 3]) -> u8 {
    let [r, g, b] = rgb.map(|c| (u16::from(c) + 25) / 51);
    let cube = (r * 36 + g * 6 + b) as u8;
    let sum: u32 = rgb.iter().map(|&c| u32::from(c)).sum();
    let step = ((sum * u32::from(GREYS + 1) + 382) / 765).clamp(1, u32::from(GREYS));
    let grey = CUBE + (step - 1) as u8;
    if distance(rgb, colour(grey)) < distance(rgb, colour(cube)) {
        grey
    } else {
        cube
    }
}

fn distance(a: [u8; 3], b: [u8; 3]) -> u32 {
    a.iter()
        .zip(b)
        .map(|(&a, b)| u32::from(a.abs_diff(b)).pow(2))
        .sum()
}

/// Turns frames into palette entries, each pixel that did not change since the previous frame transparent: a
/// swarm moves little between frames, so most of a frame compresses to runs of the transparent entry.
pub struct Indexer {
    /// The entry each pixel shows so far.
    shown: Vec<u8>,
}

impl Indexer {
    /// An indexer for frames of `pixels` pixels, before the first frame.
    pub fn new(pixels: usize) -> Self {
        Self {
            shown: vec![TRANSPARENT; pixels],
        }
    }

    /// The entries of an opaque RGBA frame of the indexer's size, into `entries`.
    pub fn index(&mut self, rgba: &[u8], entries: &mut Vec<u8>) {
        entries.clear();
        // Drawings are mostly runs of one colour: map a colour once per run.
        let mut last = ([0; 3], nearest([0; 3]));
        entries.extend(
            rgba.chunks_exact(4)
                .zip(&mut self.shown)
                .map(|(pixel, shown)| {
                    let rgb = [pixel[0], pixel[1], pixel[2]];
                    if rgb != last.0 {
                        last = (rgb, nearest(rgb));
                    }
                    let entry = last.1;
                    if entry == *shown {
                        TRANSPARENT
                    } else {
                        *shown = entry;
                        entry
                    }
                }),
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_colour_of_the_palette_maps_to_itself() {
        for index in 0..TRANSPARENT {
            let rgb = colour(index);
            assert_eq!(colour(nearest(rgb)), rgb, "entry {index}");
        }
        assert_eq!(rgb_table().len(), 768);
    }

    #[test]
    fn a_colour_maps_to_the_nearest_entry_to_within_rounding() {
        let levels = (0..=255).step_by(15);
        for r in levels.clone() {
            for g in levels.clone() {
                for b in levels.clone() {
                    let rgb = [r, g, b];
                    let best = (0..TRANSPARENT)
                        .map(|i| distance(rgb, colour(i)))
                        .min()
                        .unwrap_or_default();
                    let got = distance(rgb, colour(nearest(rgb)));
                    assert!(got <= best + 8, "{rgb:?}: {got} > {best}");
                }
            }
        }
    }

    #[test]
    fn unchanged_pixels_become_transparent() {
        let mut indexer = Indexer::new(2);
        let mut entries = Vec::new();
        indexer.index(&[255, 0, 0, 255, 0, 0, 255, 255], &mut entries);
        assert_eq!(entries, [nearest([255, 0, 0]), nearest([0, 0, 255])]);
        indexer.index(&[255, 0, 0, 255, 255, 255, 255, 255], &mut entries);
        assert_eq!(entries, [TRANSPARENT, nearest([255, 255, 255])]);
    }
}
