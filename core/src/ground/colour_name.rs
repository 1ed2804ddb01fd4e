//! Everyday colour names of observed surface colours, so that prompts can filter by colour
//! ("the yellow one"). Hue and saturation carry the name; brightness only splits orange and
//! yellow from brown, because shading darkens every surface.

/// The colour name of a mean RGB in [0, 1]: one of `query::lexicon::COLOURS`, or "grey" for
/// unsaturated colours.
pub fn colour_name(rgb: [f64; 3]) -> &'static str {
    let [r, g, b] = rgb;
    let max = r.max(g).max(b);
    let min = r.min(g).min(b);
    let chroma = max - min;
    if max <= 0.0 || chroma / max < 0.2 {
        return "grey";
    }
    let hue = if max == r {
        60.0 * ((g - b) / chroma).rem_euclid(6.0)
    } else if max == g {
        60.0 * ((b - r) / chroma + 2.0)
    } else {
        60.0 * ((r - g) / chroma + 4.0)
    };
    let bright = max >= 0.6;
    match hue {
        h if !(12.0..330.0).contains(&h) => {
            if chroma / max < 0.45 && bright {
                "pink"
            } else {
                "red"
            }
        }
        h if h < 42.0 => {
            if bright {
                "orange"
            } else {
                "brown"
            }
        }
        h if h < 70.0 => {
            if bright {
                "yellow"
            } else {
                "brown"
            }
        }
        h if h < 170.0 => "green",
        h if h < 260.0 => "blue",
        _ => "purple",
    }
}

/// Mean colour in [0, 1] of the pixels a mask (255 inside) covers.
pub fn mean_colour(image: &image::RgbImage, mask: &image::GrayImage) -> Option<[f64; 3]> {
    mean_surface_colour(
        image
            .pixels()
            .zip(mask.pixels())
            .filter(|(_, m)| m[0] > 0)
            .map(|(p, _)| p),
    )
}

/// Mean colour in [0, 1] of pixels, leaving out clipped highlights and near-black pixels,
/// which say little about the surface colour.
pub fn mean_surface_colour<'a>(
    pixels: impl Iterator<Item = &'a image::Rgb<u8>>,
) -> Option<[f64; 3]> {
    let mut sum = [0.0; 3];
    let mut n = 0usize;
    for p in pixels {
        if p.0.iter().any(|c| *c >= 250) || p.0.iter().map(|c| *c as u32).sum::<u32>() <= 30 {
            continue;
        }
        for c in 0..3 {
            sum[c] += p[c] as f64 / 255.0;
        }
        n += 1;
    }
    (n > 0).then(|| sum.map(|s| s / n as f64))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::catalog::FruitCatalog;

    #[test]
    fn catalog_colours_get_the_names_people_use() {
        let c = FruitCatalog::builtin();
        let name = |fruit: &str, stage: &str| {
            colour_name(c.get(fruit).unwrap().stage(stage).unwrap().color)
        };
        assert_eq!(name("banana", "ripe"), "yellow");
        assert_eq!(name("banana", "unripe"), "green");
        assert_eq!(name("lemon", "ripe"), "yellow");
        assert_eq!(name("lime", "ripe"), "green");
        assert_eq!(name("tomato", "ripe"), "red");
        assert_eq!(name("apple", "ripe"), "red");
        assert_eq!(name("orange", "ripe"), "orange");
        assert_eq!(name("kiwi", "ripe"), "brown");
        assert_eq!(name("avocado", "unripe"), "green");
        assert_eq!(colour_name([0.5, 0.5, 0.52]), "grey");
    }

    #[test]
    fn shading_does_not_rename_a_saturated_colour() {
        // A ripe banana under 75% shading is still yellow; a lime at 40% still green.
        assert_eq!(
            colour_name([0.94 * 0.75, 0.80 * 0.75, 0.22 * 0.75]),
            "yellow"
        );
        assert_eq!(colour_name([0.42 * 0.4, 0.68 * 0.4, 0.18 * 0.4]), "green");
    }
}
