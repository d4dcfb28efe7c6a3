//! Hot loops compiled for the processor they run on. The release build targets every x86-64
//! (SSE2: two f64 a step); where the processor has AVX2, [`fast`] runs the same code built
//! for it (four a step). Only the width changes: Rust never fuses a multiply and an add on its
//! own, and each operation stays correctly rounded, so both builds give the same numbers.

/// Runs `f`, built for AVX2 where the processor has it. `f` and what it calls with
/// `#[inline(always)]` are compiled into that build; anything not inlined stays generic.
#[inline(always)]
pub fn fast<T>(f: impl FnOnce() -> T) -> T {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: AVX2 was just detected on this processor, all that `with_avx2` requires.
        #[allow(unsafe_code)]
        return unsafe { with_avx2(f) };
    }
    f()
}

/// `f()`, with AVX2 enabled for the code inlined into it.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn with_avx2<T>(f: impl FnOnce() -> T) -> T {
    f()
}

/// The largest of `values` that is not NaN (−∞ when none is) and how many are not NaN, in a
/// loop the compiler vectorises: eight running maxima (the order of a maximum does not matter).
#[inline(always)]
pub fn max_and_finite(values: &[f32]) -> (f32, usize) {
    const W: usize = 8;
    let mut top = [f32::NEG_INFINITY; W];
    let mut finite = [0u32; W];
    let mut chunks = values.chunks_exact(W);
    for c in &mut chunks {
        for i in 0..W {
            // NaN fails the comparison, so it never becomes a maximum
            top[i] = if c[i] > top[i] { c[i] } else { top[i] };
            finite[i] += u32::from(c[i].is_finite());
        }
    }
    let (mut best, mut n) = (f32::NEG_INFINITY, 0usize);
    for &v in chunks.remainder() {
        best = if v > best { v } else { best };
        n += usize::from(v.is_finite());
    }
    for i in 0..W {
        best = if top[i] > best { top[i] } else { best };
        n += finite[i] as usize;
    }
    (best, n)
}

#[cfg(test)]
mod tests {
    use super::{fast, max_and_finite};

    #[test]
    fn the_maximum_and_count_are_those_of_a_plain_loop() {
        let mut x = 0x2545_f491u32;
        let values: Vec<f32> = (0..1003)
            .map(|i| {
                x ^= x << 13;
                x ^= x >> 17;
                x ^= x << 5;
                match i % 97 {
                    0 => f32::NAN,
                    1 => f32::INFINITY,
                    _ => (x % 10_000) as f32 - 5000.0,
                }
            })
            .collect();
        for n in [0, 1, 7, 8, 9, 500, 1003] {
            let v = &values[..n];
            let plain = v
                .iter()
                .filter(|x| !x.is_nan())
                .fold(f32::NEG_INFINITY, |a, &b| a.max(b));
            let count = v.iter().filter(|x| x.is_finite()).count();
            assert_eq!(fast(|| max_and_finite(v)), (plain, count), "{n}");
        }
        assert_eq!(max_and_finite(&[f32::NAN; 20]), (f32::NEG_INFINITY, 0));
    }
}
