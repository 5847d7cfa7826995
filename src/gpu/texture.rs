//! Texture addressing and filtering (`docs/architecture.md` "Textures": nearest and bilinear
//! sampling defined once, texel centers at +0.5).
//!
//! Coordinates are in texels: texel i covers [i, i + 1) and its center is i + 0.5 (window
//! coordinates of a render target read as a texture are already in these units). Nearest
//! takes texel ⌊x⌋; bilinear blends the two texels whose centers surround x with weight
//! `f = (x − 0.5) − ⌊x − 0.5⌋` on the second, in each axis, as
//! `(t00·(1 − fx) + t10·fx)·(1 − fy) + (t01·(1 − fx) + t11·fx)·fy` in f64. Texel indices
//! outside the texture wrap (`GL_REPEAT`) or clamp (`GL_CLAMP_TO_EDGE`).

/// How a texture is filtered.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum Filter {
    /// The texel whose center is nearest.
    Nearest,
    /// Bilinear interpolation of the four nearest texel centers.
    Bilinear,
}

/// What a texel index outside the texture reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum Wrap {
    /// `GL_REPEAT`: the index modulo the size.
    Repeat,
    /// `GL_CLAMP_TO_EDGE`: the nearest edge texel.
    ClampToEdge,
}

/// The texel a texel index addresses in a texture of `size` texels. An index inside the
/// texture, or one texel past either end (a linear filter's second tap at a border), is
/// wrapped without the integer division of `rem_euclid`, with the same result (the tables of
/// `ssv-optimized`, 1 thread: `rem_euclid` was 6 % of its profile).
fn address(i: i64, size: u32, wrap: Wrap) -> u32 {
    let n = i64::from(size);
    match wrap {
        Wrap::Repeat if (0..n).contains(&i) => i as u32,
        Wrap::Repeat if i == -1 => size - 1,
        Wrap::Repeat if i == n => 0,
        Wrap::Repeat => i.rem_euclid(n) as u32,
        Wrap::ClampToEdge => i.clamp(0, n - 1) as u32,
    }
}

/// `⌊x⌋`, the same bits as `f64::floor` (without SSE4.1 that is a call into libm, 2 % of
/// `ssv-optimized`'s profile): below 2⁵², truncation through `i64` is exact and a negative
/// non-integer is one above its floor; at or above 2⁵² (and for NaN and infinities) `x` is
/// its own floor and `f64::floor` is kept. A zero keeps its sign.
fn floor(x: f64) -> f64 {
    const EXACT: f64 = (1u64 << 52) as f64;
    if x.abs() < EXACT {
        let t = (x as i64 as f64).copysign(x);
        if t > x {
            t - 1.0
        } else {
            t
        }
    } else {
        x.floor()
    }
}

/// The texel nearest coordinate `x` (module doc).
pub fn nearest(x: f64, size: u32, wrap: Wrap) -> u32 {
    address(floor(x) as i64, size, wrap)
}

/// The two texels of a linear filter at coordinate `x` and the weight of the second.
pub fn linear_taps(x: f64, size: u32, wrap: Wrap) -> ([u32; 2], f64) {
    let x = x - 0.5;
    let i = floor(x);
    let f = x - i;
    let i = i as i64;
    ([address(i, size, wrap), address(i + 1, size, wrap)], f)
}

/// Sample a `size[0]`×`size[1]` texture at texel coordinates (x, y), reading texel (i, j)
/// with `texel(i, j)` (j along the second axis).
pub fn sample_2d(
    x: f64,
    y: f64,
    size: [u32; 2],
    wrap: Wrap,
    filter: Filter,
    texel: impl Fn(u32, u32) -> f64,
) -> f64 {
    match filter {
        Filter::Nearest => texel(nearest(x, size[0], wrap), nearest(y, size[1], wrap)),
        Filter::Bilinear => {
            let ([i0, i1], fx) = linear_taps(x, size[0], wrap);
            let ([j0, j1], fy) = linear_taps(y, size[1], wrap);
            let top = texel(i0, j0) * (1.0 - fx) + texel(i1, j0) * fx;
            let bottom = texel(i0, j1) * (1.0 - fx) + texel(i1, j1) * fx;
            top * (1.0 - fy) + bottom * fy
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// [`floor`] has the bits of `f64::floor` (and [`address`] the results of `rem_euclid`
    /// and `clamp`) on signed zeros, halves, values next to integers, the 2⁵² boundary,
    /// huge values, infinities and NaN.
    #[test]
    fn floor_and_address_agree_with_the_library() {
        let two52 = (1u64 << 52) as f64;
        let mut xs = vec![0.0, -0.0, f64::INFINITY, f64::NEG_INFINITY, 1e300, -1e300];
        for base in [0.5, 1.0, 3.0, 127.0, 128.0, two52, 2.0 * two52, 1e18, 1e19] {
            for x in [base, base.next_up(), base.next_down()] {
                xs.extend([x, -x]);
            }
        }
        for k in -1000..1000 {
            xs.push(k as f64 * 0.37);
        }
        for x in xs {
            assert_eq!(floor(x).to_bits(), x.floor().to_bits(), "floor({x:e})");
        }
        assert!(floor(f64::NAN).is_nan());
        for size in [1u32, 2, 5, 128, 256] {
            let n = i64::from(size);
            for i in (-3 * n - 2..=3 * n + 2).chain([i64::MIN, i64::MAX]) {
                assert_eq!(address(i, size, Wrap::Repeat), i.rem_euclid(n) as u32);
                assert_eq!(
                    address(i, size, Wrap::ClampToEdge),
                    i.clamp(0, n - 1) as u32
                );
            }
        }
    }

    #[test]
    fn nearest_and_wrapping() {
        assert_eq!(nearest(0.0, 4, Wrap::Repeat), 0);
        assert_eq!(nearest(3.99, 4, Wrap::Repeat), 3);
        assert_eq!(nearest(4.0, 4, Wrap::Repeat), 0);
        assert_eq!(nearest(-0.5, 4, Wrap::Repeat), 3);
        assert_eq!(nearest(4.0, 4, Wrap::ClampToEdge), 3);
        assert_eq!(nearest(-7.0, 4, Wrap::ClampToEdge), 0);
    }

    #[test]
    fn bilinear_is_exact_at_centers_and_linear_between() {
        let t = |i: u32, j: u32| (i * 10 + j) as f64;
        let s = |x, y, w| sample_2d(x, y, [4, 4], w, Filter::Bilinear, t);
        // At a texel center: that texel.
        assert_eq!(s(2.5, 1.5, Wrap::ClampToEdge), 21.0);
        // Halfway between the centers of texels 1 and 2: their mean.
        assert_eq!(s(2.0, 1.5, Wrap::ClampToEdge), 16.0);
        // Beyond the last center: clamped to the edge texel, or blended with the first.
        assert_eq!(s(3.9, 0.5, Wrap::ClampToEdge), 30.0);
        assert!((s(3.9, 0.5, Wrap::Repeat) - (30.0 * 0.6 + 0.0 * 0.4)).abs() < 1e-12);
        assert_eq!(
            sample_2d(1.7, 2.2, [4, 4], Wrap::Repeat, Filter::Nearest, t),
            12.0
        );
    }
}
