//! Validated numbers: what every numeric input (a flag, a scenario
//! parameter, a model field) becomes before library code computes with it.
//! A NaN compares false with everything, so an unchecked NaN reads as
//! "within limits" wherever a limit is tested with `>`; an infinity or a
//! subnormal makes products overflow or vanish. Both are refused here, at
//! the boundary, with the range that was expected.

/// A number outside the range its use needs.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{value} is not {expected}")]
pub struct InvalidNumber {
    pub value: f64,
    /// The range, in words ("a positive finite number", "in (0, 0.1]").
    pub expected: &'static str,
}

/// `value` if it is finite, positive and normal (not subnormal: products
/// with it would underflow to zero).
pub fn positive(value: f64) -> Result<f64, InvalidNumber> {
    if value.is_finite() && value > 0.0 && value.is_normal() {
        Ok(value)
    } else {
        Err(InvalidNumber {
            value,
            expected: "a positive finite number",
        })
    }
}

/// `value` if it is finite and in `[lo, hi]`.
pub fn within(value: f64, lo: f64, hi: f64, expected: &'static str) -> Result<f64, InvalidNumber> {
    if value.is_finite() && value >= lo && value <= hi {
        Ok(value)
    } else {
        Err(InvalidNumber { value, expected })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn non_finite_zero_negative_and_subnormal_values_are_not_positive() {
        for v in [
            f64::NAN,
            f64::INFINITY,
            -f64::INFINITY,
            0.0,
            -0.0,
            -1.0,
            1e-310,
        ] {
            assert!(positive(v).is_err(), "{v}");
        }
        assert_eq!(positive(3.6), Ok(3.6));
        assert_eq!(positive(f64::MIN_POSITIVE), Ok(f64::MIN_POSITIVE));
    }

    #[test]
    fn a_range_refuses_nan_and_the_values_outside_it() {
        assert!(within(f64::NAN, 0.0, 1.0, "in [0, 1]").is_err());
        assert!(within(1.5, 0.0, 1.0, "in [0, 1]").is_err());
        assert_eq!(within(1.0, 0.0, 1.0, "in [0, 1]"), Ok(1.0));
        let e = within(-2.0, 0.0, 1.0, "in [0, 1]").unwrap_err();
        assert_eq!(e.to_string(), "-2 is not in [0, 1]");
    }
}
