//! Least-squares fits the studies report (messages against modules, log–log
//! scaling), one formula for all of them.

use serde::Serialize;

/// An ordinary least-squares line `y = slope·x + intercept`, and its R².
#[derive(Copy, Clone, Debug, PartialEq, Serialize)]
pub struct LinearFit {
    pub slope: f64,
    pub intercept: f64,
    pub r2: f64,
}

impl LinearFit {
    /// The line's value at `x`.
    pub fn at(&self, x: f64) -> f64 {
        self.slope * x + self.intercept
    }
}

/// Least-squares fit of `y = slope·x + intercept` through `points`; `None`
/// with fewer than two distinct finite x. Non-finite points are left out.
pub fn linear_fit(points: &[(f64, f64)]) -> Option<LinearFit> {
    let p: Vec<(f64, f64)> = points
        .iter()
        .copied()
        .filter(|(x, y)| x.is_finite() && y.is_finite())
        .collect();
    if p.len() < 2 {
        return None;
    }
    let n = p.len() as f64;
    let mx = p.iter().map(|q| q.0).sum::<f64>() / n;
    let my = p.iter().map(|q| q.1).sum::<f64>() / n;
    let sxx: f64 = p.iter().map(|q| (q.0 - mx).powi(2)).sum();
    let sxy: f64 = p.iter().map(|q| (q.0 - mx) * (q.1 - my)).sum();
    let syy: f64 = p.iter().map(|q| (q.1 - my).powi(2)).sum();
    if sxx == 0.0 {
        return None;
    }
    let slope = sxy / sxx;
    let r2 = if syy == 0.0 {
        1.0
    } else {
        sxy * sxy / (sxx * syy)
    };
    Some(LinearFit {
        slope,
        intercept: my - slope * mx,
        r2,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_linear_fit_matches_the_closed_form() {
        // (0, 0), (1, 1), (2, 1): x̄ = 1, ȳ = 2/3, Sxx = 2, Sxy = 1,
        // Syy = 2/3: slope 1/2, intercept 2/3 − 1/2 = 1/6, R² = 1/(2·2/3) = 3/4.
        let f = linear_fit(&[(0.0, 0.0), (1.0, 1.0), (2.0, 1.0)]).unwrap();
        assert!((f.slope - 0.5).abs() < 1e-12, "{f:?}");
        assert!((f.intercept - 1.0 / 6.0).abs() < 1e-12, "{f:?}");
        assert!((f.r2 - 0.75).abs() < 1e-12, "{f:?}");
        assert!((f.at(4.0) - (2.0 + 1.0 / 6.0)).abs() < 1e-12);
    }

    #[test]
    fn the_linear_fit_recovers_an_exact_line_and_refuses_a_vertical_one() {
        let pts: Vec<(f64, f64)> = [824.0, 3335.0, 13420.0]
            .iter()
            .map(|&x| (x, 2.97 * x - 40.0))
            .chain([(f64::NAN, 1.0), (1.0, f64::INFINITY)])
            .collect();
        let f = linear_fit(&pts).unwrap();
        assert!((f.slope - 2.97).abs() < 1e-12, "{f:?}");
        assert!((f.intercept + 40.0).abs() < 1e-8, "{f:?}");
        assert!((f.r2 - 1.0).abs() < 1e-12, "{f:?}");
        assert!(linear_fit(&[(1.0, 1.0)]).is_none());
        assert!(linear_fit(&[(3.0, 1.0), (3.0, 2.0)]).is_none());
    }
}
