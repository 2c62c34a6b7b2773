//! Number parsing for log tokens, without allocation.
//!
//! Most numbers in a log are short decimals (`1.234`, `-0.00613592`,
//! `1190000000.017285`). For those, the digits form an integer `m` and the value is
//! `m / 10^k`; when `m` and `10^k` are both exactly representable, one IEEE division is
//! correctly rounded, so the result is exactly what a full parser would give (Clinger's
//! fast path). Anything else (exponents, many digits, `inf`, `nan`) goes to the
//! standard library's parser, which is correct for every input.

/// Powers of ten exactly representable as `f64` (10^0 … 10^22).
const POW10_F64: [f64; 23] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
    1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
];

/// Powers of ten exactly representable as `f32` (10^0 … 10^10).
const POW10_F32: [f32; 11] = [1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10];

/// A plain decimal split into (negative, mantissa, digits after the point).
pub(crate) type DecimalSplit = (bool, u64, usize);

/// Splits a plain decimal `[+-]digits[.digits]` into (negative, mantissa, digits after
/// the point). `None` when the token is not of that form or has more than 19 digits.
#[inline]
pub(crate) fn plain_decimal(s: &[u8]) -> Option<DecimalSplit> {
    let (neg, body) = match s.first()? {
        b'-' => (true, &s[1..]),
        b'+' => (false, &s[1..]),
        _ => (false, s),
    };
    if body.is_empty() || body.len() > 20 {
        return None;
    }
    let mut m: u64 = 0;
    let mut digits = 0usize;
    let mut frac: Option<usize> = None;
    for (i, &c) in body.iter().enumerate() {
        match c {
            b'0'..=b'9' => {
                if digits == 19 {
                    return None;
                }
                m = m * 10 + (c - b'0') as u64;
                digits += 1;
            }
            b'.' if frac.is_none() => frac = Some(i),
            _ => return None,
        }
    }
    if digits == 0 {
        return None;
    }
    let k = match frac {
        Some(i) => body.len() - i - 1,
        None => 0,
    };
    Some((neg, m, k))
}

/// Parses a float token as `f64`; `None` when it is not a number.
#[inline]
pub(crate) fn parse_f64(s: &[u8]) -> Option<f64> {
    if let Some((neg, m, k)) = plain_decimal(s) {
        if m < (1u64 << 53) && k < POW10_F64.len() {
            let v = m as f64 / POW10_F64[k];
            return Some(if neg { -v } else { v });
        }
    }
    slow_parse::<f64>(s)
}

/// Parses a float token as `f32` (directly, not through `f64`, so that it rounds once).
/// (The reader takes the split from the tokenizer: [`f32_of_token`].)
#[cfg(test)]
pub(crate) fn parse_f32(s: &[u8]) -> Option<f32> {
    f32_of_token(s, plain_decimal(s))
}

/// The `f32` of token `s`, given its [`plain_decimal`] split (found while the token
/// was delimited, by [`crate::tokens::Tokens::next_decimal`]).
#[inline]
pub(crate) fn f32_of_token(s: &[u8], plain: Option<DecimalSplit>) -> Option<f32> {
    if let Some((neg, m, k)) = plain {
        if m < (1u64 << 24) && k < POW10_F32.len() {
            let v = m as f32 / POW10_F32[k];
            return Some(if neg { -v } else { v });
        }
    }
    slow_parse::<f32>(s)
}

/// Parses a signed decimal integer token; `None` when it is not one or overflows.
#[inline]
pub(crate) fn parse_i64(s: &[u8]) -> Option<i64> {
    let (neg, body) = match s.first()? {
        b'-' => (true, &s[1..]),
        b'+' => (false, &s[1..]),
        _ => (false, s),
    };
    if body.is_empty() {
        return None;
    }
    let mut m: i64 = 0;
    for &c in body {
        if !c.is_ascii_digit() {
            return None;
        }
        let d = (c - b'0') as i64;
        m = if neg {
            m.checked_mul(10)?.checked_sub(d)?
        } else {
            m.checked_mul(10)?.checked_add(d)?
        };
    }
    Some(m)
}

/// The standard library's parser, for the tokens the fast path does not take.
fn slow_parse<T: std::str::FromStr>(s: &[u8]) -> Option<T> {
    std::str::from_utf8(s).ok()?.parse().ok()
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn same64(a: Option<f64>, b: Option<f64>) -> bool {
        match (a, b) {
            (Some(a), Some(b)) => a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan()),
            (None, None) => true,
            _ => false,
        }
    }

    fn same32(a: Option<f32>, b: Option<f32>) -> bool {
        same64(a.map(f64::from), b.map(f64::from))
    }

    #[test]
    fn plain_numbers() {
        assert_eq!(parse_f64(b"1190000000.017285"), Some(1190000000.017285));
        assert_eq!(parse_f64(b"-0.00613592"), Some(-0.00613592));
        assert_eq!(parse_f64(b"+4"), Some(4.0));
        assert_eq!(parse_f64(b"1e-3"), Some(1e-3));
        assert_eq!(parse_f64(b".5"), Some(0.5));
        assert_eq!(parse_f64(b"5."), Some(5.0));
        assert!(parse_f64(b"inf").unwrap().is_infinite());
        assert!(parse_f64(b"NaN").unwrap().is_nan());
        assert_eq!(parse_f64(b"-0"), Some(-0.0));
        for bad in [
            &b""[..],
            b"-",
            b".",
            b"1.2.3",
            b"abc",
            b"1,5",
            b"--1",
            b"0x10",
        ] {
            assert_eq!(parse_f64(bad), None, "{:?}", std::str::from_utf8(bad));
            assert_eq!(parse_f32(bad), None);
        }
        assert_eq!(parse_f32(b"0.512"), Some(0.512f32));
        assert_eq!(parse_i64(b"-9223372036854775808"), Some(i64::MIN));
        assert_eq!(parse_i64(b"9223372036854775808"), None);
        assert_eq!(parse_i64(b"12a"), None);
        assert_eq!(parse_i64(b"1.0"), None);
        assert_eq!(parse_i64(b"-"), None);
    }

    proptest! {
        #[test]
        fn f64_agrees_with_std(x in any::<f64>(), digits in 0usize..12, s in "[-+]?[0-9]{0,12}(\\.[0-9]{0,12})?") {
            let shortest = x.to_string();
            prop_assert!(same64(parse_f64(shortest.as_bytes()), Some(x)), "{}", shortest);
            let fixed = format!("{x:.digits$}");
            prop_assert!(same64(parse_f64(fixed.as_bytes()), fixed.parse().ok()), "{}", fixed);
            prop_assert!(same64(parse_f64(s.as_bytes()), s.parse().ok()), "{}", s);
        }

        #[test]
        fn f32_agrees_with_std(x in any::<f32>(), s in "[-+]?[0-9]{0,9}(\\.[0-9]{0,9})?") {
            let shortest = x.to_string();
            prop_assert!(same32(parse_f32(shortest.as_bytes()), Some(x)), "{}", shortest);
            prop_assert!(same32(parse_f32(s.as_bytes()), s.parse().ok()), "{}", s);
        }

        #[test]
        fn i64_agrees_with_std(x in any::<i64>(), s in "[-+]?[0-9]{0,20}") {
            prop_assert_eq!(parse_i64(x.to_string().as_bytes()), Some(x));
            prop_assert_eq!(parse_i64(s.as_bytes()), s.parse::<i64>().ok());
        }
    }
}
