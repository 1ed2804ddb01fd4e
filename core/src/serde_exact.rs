//! Fixed-size arrays read from files exactly: serde's `[T; N]` takes the first N elements of
//! a longer list and drops the rest silently (a profile's `[a, b, c, 99, "junk"]` loaded with
//! the same hash as `[a, b, c]`). These read a list and refuse any other length.

use serde::de::{Deserialize, Deserializer, Error};

fn exact<T, E: Error, const N: usize>(items: Vec<T>) -> Result<[T; N], E> {
    let n = items.len();
    items
        .try_into()
        .map_err(|_| E::invalid_length(n, &format!("a list of exactly {N}").as_str()))
}

/// `[T; N]` from a list of exactly N.
pub fn array<'de, D: Deserializer<'de>, T: Deserialize<'de>, const N: usize>(
    d: D,
) -> Result<[T; N], D::Error> {
    exact(Vec::<T>::deserialize(d)?)
}

/// `Option<[T; N]>` from a list of exactly N, when the field is there (give the field
/// `#[serde(default)]` too, so that it may be left out).
pub fn optional_array<'de, D: Deserializer<'de>, T: Deserialize<'de>, const N: usize>(
    d: D,
) -> Result<Option<[T; N]>, D::Error> {
    array(d).map(Some)
}

/// `[[T; N]; M]` from a list of exactly M lists of exactly N.
pub fn matrix<'de, D: Deserializer<'de>, T: Deserialize<'de>, const N: usize, const M: usize>(
    d: D,
) -> Result<[[T; N]; M], D::Error> {
    let rows = Vec::<Vec<T>>::deserialize(d)?
        .into_iter()
        .map(exact::<T, D::Error, N>)
        .collect::<Result<Vec<_>, _>>()?;
    exact(rows)
}

#[cfg(test)]
mod tests {
    #[derive(serde::Deserialize, Debug)]
    struct Probe {
        #[serde(deserialize_with = "super::array")]
        colour: [f32; 3],
        #[serde(deserialize_with = "super::matrix")]
        mix: [[f32; 3]; 2],
    }

    #[test]
    fn lists_of_the_wrong_length_are_refused_not_cut() {
        let ok: Probe = toml::from_str("colour = [1, 2, 3]\nmix = [[1, 2, 3], [4, 5, 6]]").unwrap();
        assert_eq!(ok.colour, [1.0, 2.0, 3.0]);
        assert_eq!(ok.mix[1], [4.0, 5.0, 6.0]);
        for bad in [
            "colour = [1, 2, 3, 99]\nmix = [[1, 2, 3], [4, 5, 6]]",
            "colour = [1, 2]\nmix = [[1, 2, 3], [4, 5, 6]]",
            "colour = [1, 2, 3]\nmix = [[1, 2, 3], [4, 5, 6, 7]]",
            "colour = [1, 2, 3]\nmix = [[1, 2, 3], [4, 5, 6], [7, 8, 9]]",
        ] {
            let err = toml::from_str::<Probe>(bad).unwrap_err().to_string();
            assert!(err.contains("exactly"), "{bad}: {err}");
        }
    }
}
