//! Ranks with ties given their average rank (1-based), as scipy.stats.rankdata does.

pub fn average_ranks(x: &[f64]) -> Vec<f64> {
    let mut order: Vec<usize> = (0..x.len()).collect();
    order.sort_by(|&a, &b| x[a].total_cmp(&x[b]));
    let mut ranks = vec![0.0; x.len()];
    let mut i = 0;
    while i < order.len() {
        let mut j = i;
        while j + 1 < order.len() && x[order[j + 1]] == x[order[i]] {
            j += 1;
        }
        let rank = (i + j) as f64 / 2.0 + 1.0;
        for &k in &order[i..=j] {
            ranks[k] = rank;
        }
        i = j + 1;
    }
    ranks
}

/// Sizes of the groups of tied values.
pub(crate) fn tie_groups(x: &[f64]) -> Vec<usize> {
    let mut sorted = x.to_vec();
    sorted.sort_by(f64::total_cmp);
    let mut out = Vec::new();
    let mut i = 0;
    while i < sorted.len() {
        let mut j = i;
        while j + 1 < sorted.len() && sorted[j + 1] == sorted[i] {
            j += 1;
        }
        out.push(j - i + 1);
        i = j + 1;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ties_share_their_average_rank() {
        // scipy.stats.rankdata([3, 1, 4, 1, 5]) -> [3., 1.5, 4., 1.5, 5.]
        assert_eq!(
            average_ranks(&[3.0, 1.0, 4.0, 1.0, 5.0]),
            [3.0, 1.5, 4.0, 1.5, 5.0]
        );
        assert_eq!(tie_groups(&[3.0, 1.0, 4.0, 1.0, 5.0]), [2, 1, 1, 1]);
    }
}
