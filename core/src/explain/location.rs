//! The TactEx paper's rule-based location words from workspace coordinates.

/// Objects this far (m) from the table centre line are "left"/"right" or "front"/"back".
pub const LOCATION_BAND_M: f64 = 0.06;

/// "left front", "centre back", "centre", ... from table coordinates (x right, y back).
pub fn location_words(x: f64, y: f64) -> String {
    let lr = if x < -LOCATION_BAND_M {
        "left"
    } else if x > LOCATION_BAND_M {
        "right"
    } else {
        "centre"
    };
    let fb = if y < -LOCATION_BAND_M {
        "front"
    } else if y > LOCATION_BAND_M {
        "back"
    } else {
        "centre"
    };
    match (lr, fb) {
        ("centre", "centre") => "centre".into(),
        (lr, fb) => format!("{lr} {fb}"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn locations_follow_the_table_frame() {
        assert_eq!(location_words(-0.2, -0.1), "left front");
        assert_eq!(location_words(0.2, 0.1), "right back");
        assert_eq!(location_words(0.0, 0.0), "centre");
        assert_eq!(location_words(0.0, 0.2), "centre back");
    }
}
