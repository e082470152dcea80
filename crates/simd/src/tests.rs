//! The x86-64 lanes against the portable ones, bit for bit, for every operation, on values
//! that reach every corner of IEEE arithmetic (signed zeros, subnormals, the `i32` range's
//! ends, infinities, NaN).

use crate::portable as p;

/// Edge values, then a spread of ordinary ones.
fn values() -> Vec<f32> {
    let mut v = vec![
        0.0,
        -0.0,
        1.0,
        -1.0,
        0.5,
        -0.5,
        1.5,
        -1.5,
        2.5,
        -2.5,
        1e-40,
        -1e-40,
        f32::MIN_POSITIVE,
        2_147_483_520.0,
        2_147_483_648.0,
        -2_147_483_648.0,
        -2_147_483_904.0,
        3e9,
        -3e9,
        f32::MAX,
        f32::MIN,
        f32::INFINITY,
        f32::NEG_INFINITY,
        f32::NAN,
        -f32::NAN,
    ];
    let mut s = 0x2545_f491_u32;
    for _ in 0..200 {
        s ^= s << 13;
        s ^= s >> 17;
        s ^= s << 5;
        v.push((s as f32 / u32::MAX as f32 - 0.5) * 1000.0);
    }
    v
}

/// Groups of `n` lanes drawn from [`values`], shifted so that every value meets every lane.
fn groups<const N: usize>() -> Vec<([f32; N], [f32; N])> {
    let v = values();
    let mut out = Vec::new();
    for i in 0..v.len() {
        for shift in [1, 3, 7] {
            let a = std::array::from_fn(|k| v[(i + k) % v.len()]);
            let b = std::array::from_fn(|k| v[(i + k * shift + 5) % v.len()]);
            out.push((a, b));
        }
    }
    out
}

fn bits<const N: usize>(a: [f32; N]) -> [u32; N] {
    a.map(f32::to_bits)
}

#[test]
fn trunc_matches() {
    for x in values() {
        assert_eq!(crate::trunc_i32(x), p::trunc_i32(x), "{x}");
        #[cfg(target_arch = "x86_64")]
        assert_eq!(crate::sse2::trunc_i32(x), p::trunc_i32(x), "{x}");
    }
}

/// Every four-lane operation of `$q` (SSE2 or whichever is in use) against the portable one.
macro_rules! check4 {
    ($q:path) => {{
        use $q as q;
        for (a, b) in groups::<4>() {
            let (pa, pb) = (p::F32x4::from_array(a), p::F32x4::from_array(b));
            let (qa, qb) = (q::F32x4::from_array(a), q::F32x4::from_array(b));
            let same = |x: p::F32x4, y: q::F32x4| {
                assert_eq!(bits(x.to_array()), bits(y.to_array()), "{a:?} {b:?}")
            };
            same(pa + pb, qa + qb);
            same(pa - pb, qa - qb);
            same(pa * pb, qa * qb);
            same(pa / pb, qa / qb);
            same(-pa, -qa);
            same(pa.abs(), qa.abs());
            same(p::F32x4::load(&a), q::F32x4::load(&a));
            same(p::F32x4::splat(a[1]), q::F32x4::splat(a[1]));
            let mut s = [0.0; 4];
            qa.store(&mut s);
            assert_eq!(bits(s), bits(a));
            let (mut pb16, mut qb16) = ([0u8; 17], [0u8; 17]);
            pa.store_le_bytes(&mut pb16[1..]);
            qa.store_le_bytes(&mut qb16[1..]);
            assert_eq!(pb16, qb16);
            let pm = [pa.ge(pb), pa.gt(pb), pa.lt(pb), pa.eq(pb)];
            let qm = [qa.ge(qb), qa.gt(qb), qa.lt(qb), qa.eq(qb)];
            for (x, y) in pm.iter().zip(&qm) {
                assert_eq!(x.bitmask(), y.bitmask(), "{a:?} {b:?}");
                assert_eq!(x.to_i32().to_array(), y.to_i32().to_array());
                same(x.select(pa, pb), y.select(qa, qb));
                assert_eq!(x.any(), y.any());
                assert_eq!(x.all(), y.all());
                assert_eq!((!*x).bitmask(), (!*y).bitmask());
                for (x2, y2) in pm.iter().zip(&qm) {
                    assert_eq!((*x & *x2).bitmask(), (*y & *y2).bitmask());
                    assert_eq!((*x | *x2).bitmask(), (*y | *y2).bitmask());
                    assert_eq!(x.and_not(*x2).bitmask(), y.and_not(*y2).bitmask());
                }
            }
            let (pi, qi) = (pa.trunc_i32(), qa.trunc_i32());
            assert_eq!(pi.to_array(), qi.to_array(), "{a:?}");
            let (pj, qj) = (pb.to_bits(), qb.to_bits());
            assert_eq!(pj.to_array(), qj.to_array());
            same(p::F32x4::from_bits(pj), q::F32x4::from_bits(qj));
            same(pi.to_f32(), qi.to_f32());
            assert_eq!((pi + pj).to_array(), (qi + qj).to_array());
            assert_eq!((pi - pj).to_array(), (qi - qj).to_array());
            for (x, y) in [
                (pi.gt(pj), qi.gt(qj)),
                (pi.lt(pj), qi.lt(qj)),
                (pi.eq(pi), qi.eq(qi)),
            ] {
                assert_eq!(x.bitmask(), y.bitmask());
                assert_eq!(
                    x.select_i32(pi, pj).to_array(),
                    y.select_i32(qi, qj).to_array()
                );
            }
            assert_eq!(
                q::I32x4::splat(pi.to_array()[2]).to_array(),
                p::I32x4::splat(pi.to_array()[2]).to_array()
            );
            assert_eq!(
                q::I32x4::from_array(pj.to_array()).to_array(),
                pj.to_array()
            );
            let bools = [a[0] > 0.0, a[1] > 0.0, a[2] < 0.0, b[0] > a[0]];
            assert_eq!(
                p::M32x4::from_bools(bools).bitmask(),
                q::M32x4::from_bools(bools).bitmask()
            );
            let c = [a, b, a.map(|x| x * 0.5), b.map(|x| x - 1.0)];
            let (pt, qt) = (
                p::F32x4::transpose(c.map(p::F32x4::from_array)),
                q::F32x4::transpose(c.map(q::F32x4::from_array)),
            );
            for (x, y) in pt.into_iter().zip(qt) {
                same(x, y);
            }
            let c3 = [c[0], c[1], c[2]];
            let (pd, qd) = (
                p::F32x4::deinterleave3(c3.map(p::F32x4::from_array)),
                q::F32x4::deinterleave3(c3.map(q::F32x4::from_array)),
            );
            let (pe, qe) = (
                p::F32x4::interleave3(c3.map(p::F32x4::from_array)),
                q::F32x4::interleave3(c3.map(q::F32x4::from_array)),
            );
            for (x, y) in pd.into_iter().zip(qd).chain(pe.into_iter().zip(qe)) {
                same(x, y);
            }
            let (e, o): ([u8; 8], [u8; 8]) = (
                std::array::from_fn(|k| a[k / 2].to_bits().to_le_bytes()[k % 4]),
                std::array::from_fn(|k| b[k / 2].to_bits().to_le_bytes()[(k + 1) % 4]),
            );
            same(
                p::F32x4::from_split_bytes(&e, &o),
                q::F32x4::from_split_bytes(&e, &o),
            );
        }
        for bits in 0..16 {
            assert_eq!(q::M32x4::from_bitmask(bits).bitmask(), bits);
            assert_eq!(p::M32x4::from_bitmask(bits).bitmask(), bits);
        }
    }};
}

/// Every eight-lane operation of `$q` against the portable one, inside the token's `run`.
macro_rules! check8 {
    ($q:path, $x8:expr) => {{
        use $q as q;
        let x8: q::X8 = $x8;
        let px = p::X8::get().unwrap();
        {
            for (a, b) in groups::<8>() {
                let (pa, pb) = (px.f32s(a), px.f32s(b));
                let (qa, qb) = (x8.f32s(a), x8.f32s(b));
                let same = |x: p::F32x8, y: q::F32x8| {
                    assert_eq!(bits(x.to_array()), bits(y.to_array()), "{a:?} {b:?}")
                };
                same(pa + pb, qa + qb);
                same(pa - pb, qa - qb);
                same(pa * pb, qa * qb);
                same(pa / pb, qa / qb);
                same(-pa, -qa);
                same(pa.abs(), qa.abs());
                same(px.load(&a), x8.load(&a));
                same(px.splat(a[3]), x8.splat(a[3]));
                let mut s = [0.0; 8];
                qa.store(&mut s);
                assert_eq!(bits(s), bits(a));
                let pm = [pa.ge(pb), pa.gt(pb), pa.lt(pb), pa.eq(pb)];
                let qm = [qa.ge(qb), qa.gt(qb), qa.lt(qb), qa.eq(qb)];
                for (x, y) in pm.iter().zip(&qm) {
                    assert_eq!(x.bitmask(), y.bitmask(), "{a:?} {b:?}");
                    assert_eq!(x.to_i32().to_array(), y.to_i32().to_array());
                    same(x.select(pa, pb), y.select(qa, qb));
                    assert_eq!((x.any(), x.all()), (y.any(), y.all()));
                    assert_eq!((!*x).bitmask(), (!*y).bitmask());
                    for (x2, y2) in pm.iter().zip(&qm) {
                        assert_eq!((*x & *x2).bitmask(), (*y & *y2).bitmask());
                        assert_eq!((*x | *x2).bitmask(), (*y | *y2).bitmask());
                        assert_eq!(x.and_not(*x2).bitmask(), y.and_not(*y2).bitmask());
                    }
                }
                let (pi, qi) = (pa.trunc_i32(), qa.trunc_i32());
                assert_eq!(pi.to_array(), qi.to_array(), "{a:?}");
                let (pj, qj) = (pb.to_bits(), qb.to_bits());
                assert_eq!(pj.to_array(), qj.to_array());
                same(p::F32x8::from_bits(pj), q::F32x8::from_bits(qj));
                same(pi.to_f32(), qi.to_f32());
                assert_eq!((pi + pj).to_array(), (qi + qj).to_array());
                assert_eq!((pi - pj).to_array(), (qi - qj).to_array());
                assert_eq!((pi * pj).to_array(), (qi * qj).to_array());
                assert_eq!((pi & pj).to_array(), (qi & qj).to_array());
                for n in [0, 1, 7, 14, 31, 32, 40] {
                    assert_eq!(
                        pj.shift_right(n).to_array(),
                        qj.shift_right(n).to_array(),
                        "{n}"
                    );
                }
                // Indices in, below and above the table: clamped alike.
                let table: Vec<f32> = (0..37).map(|k| k as f32 * 0.5 - 3.0).collect();
                let idx = (pi & px.splat_i32(63)) - px.splat_i32(13);
                let qidx = (qi & x8.splat_i32(63)) - x8.splat_i32(13);
                same(px.gather(&table, idx), x8.gather(&table, qidx));
                let edge = [-5, 0, 36, 37, i32::MIN, i32::MAX, 1, 2];
                let want: [f32; 8] = edge.map(|i| table[i.clamp(0, 36) as usize]);
                let edge = edge.map(|x| x as u32);
                assert_eq!(
                    bits(x8.gather(&table, x8.u32s(&edge)).to_array()),
                    bits(want)
                );
                assert_eq!(
                    bits(px.gather(&table, px.u32s(&edge)).to_array()),
                    bits(want)
                );
                for (x, y) in [
                    (pi.gt(pj), qi.gt(qj)),
                    (pi.lt(pj), qi.lt(qj)),
                    (pi.eq(pi), qi.eq(qi)),
                ] {
                    assert_eq!(x.bitmask(), y.bitmask());
                    assert_eq!(
                        x.select_i32(pi, pj).to_array(),
                        y.select_i32(qi, qj).to_array()
                    );
                }
                let u: [u32; 8] = pj.to_array().map(|x| x as u32);
                assert_eq!(px.u32s(&u).to_array(), x8.u32s(&u).to_array());
                assert_eq!(px.splat_i32(-7).to_array(), x8.splat_i32(-7).to_array());
                let c = [a, b, a.map(|x| x * 0.5), b.map(|x| x - 1.0)];
                let (pp, qp) = (
                    p::F32x8::interleave4(c.map(|v| px.f32s(v))),
                    q::F32x8::interleave4(c.map(|v| x8.f32s(v))),
                );
                assert_eq!(pp.map(bits), qp.map(bits));
            }
            for bits in 0..256 {
                assert_eq!(x8.mask(bits).bitmask(), bits);
                assert_eq!(px.mask(bits).bitmask(), bits);
            }
        }
    }};
}

#[test]
fn lanes4_match_portable() {
    #[cfg(target_arch = "x86_64")]
    check4!(crate::sse2);
    check4!(crate);
}

#[test]
fn lanes8_match_portable() {
    #[cfg(target_arch = "x86_64")]
    match crate::avx2::X8::get() {
        Some(x8) => check8!(crate::avx2, x8),
        None => eprintln!("no AVX2 here: only the portable lanes checked"),
    }
    check8!(crate::portable, p::X8::get().unwrap());
}

#[test]
fn prefix_sums_match() {
    let mut s = 7u32;
    for len in [0, 1, 2, 15, 16, 17, 31, 32, 33, 100, 1000] {
        let b: Vec<u8> = (0..len)
            .map(|_| {
                s = s.wrapping_mul(1_103_515_245).wrapping_add(12345);
                (s >> 16) as u8
            })
            .collect();
        for bias in [0, 1, 128, 255] {
            let mut x = b.clone();
            let mut y = b.clone();
            p::prefix_sum_biased(&mut x, bias);
            crate::prefix_sum_biased(&mut y, bias);
            assert_eq!(x, y, "{len} {bias}");
            #[cfg(target_arch = "x86_64")]
            {
                let mut z = b.clone();
                crate::sse2::prefix_sum_biased(&mut z, bias);
                assert_eq!(x, z, "{len} {bias}");
            }
        }
    }
}

#[test]
fn taps_read_what_checked_loads_read_and_clamp_to_last() {
    let a: Vec<f32> = (0..40).map(|i| i as f32 * 0.5 - 3.0).collect();
    let b: Vec<f32> = a.iter().map(|x| -x).collect();
    let off = [0, 3, 18, 21];
    let t = crate::Taps::new([&a[..], &b[..]], 3, 18).unwrap();
    assert_eq!(t.last(), 40 - 25);
    for (k, s) in [&a, &b].into_iter().enumerate() {
        for i in 0..60 {
            let at = i.min(t.last());
            let got = t.get(k, i).map(|v| v.to_array());
            let want = off.map(|o| crate::F32x4::load(&s[at + o..]).to_array());
            assert_eq!(got, want, "{k} {i}");
        }
    }
    // Too short, lengths differ, no slice.
    assert!(crate::Taps::new([&a[..24]], 3, 18).is_none());
    assert!(crate::Taps::new([&a[..25]], 3, 18).is_some());
    assert!(crate::Taps::new([&a[..], &b[..39]], 3, 18).is_none());
    assert!(crate::Taps::<0>::new([], 3, 18).is_none());
    assert!(crate::Taps::new([&a[..]], usize::MAX, 0).is_none());
}

#[test]
fn pairs_read_what_checked_loads_read_and_clamp_to_last() {
    let a: Vec<f32> = (0..40).map(|i| i as f32 * 0.5 - 3.0).collect();
    let b: Vec<f32> = a.iter().map(|x| -x).collect();
    let p = crate::Pairs::new([&a[..], &b[..]], 18).unwrap();
    assert_eq!(p.last(), 40 - 20);
    let slices = [&a, &b];
    for i in 0..60 {
        let k = [i % 2, (i / 2) % 2, 1, 0];
        let bases = [i, i + 1, i / 3, 59 - i];
        let got = p.get(k, bases).map(|v| v.to_array());
        for j in 0..4 {
            let (s, at) = (slices[k[j]], bases[j].min(p.last()));
            let want = [s[at], s[at + 1], s[at + 18], s[at + 19]];
            assert_eq!(got.map(|v| v[j]), want, "{i} {j}");
        }
    }
    // Too short, lengths differ, no slice.
    assert!(crate::Pairs::new([&a[..19]], 18).is_none());
    assert!(crate::Pairs::new([&a[..20]], 18).is_some());
    assert!(crate::Pairs::new([&a[..], &b[..39]], 18).is_none());
    assert!(crate::Pairs::<0>::new([], 18).is_none());
    assert!(crate::Pairs::new([&a[..]], usize::MAX).is_none());
}

#[test]
fn code_pairs_read_each_code_and_clamp_to_last() {
    let a: Vec<u8> = (0..41).map(|i| (i * 37 % 256) as u8).collect();
    let p1 = crate::CodePairs::<1>::new(&a, 18).unwrap();
    assert_eq!(p1.last(), 41 - 20);
    let p2 = crate::CodePairs::<2>::new(&a, 7).unwrap();
    assert_eq!(p2.last(), 20 - 9);
    let c2 = |k: usize| u16::from_le_bytes([a[2 * k], a[2 * k + 1]]) as i32;
    for i in 0..60 {
        let bases = [i, i + 1, i / 3, 59 - i];
        let got = p1.get(bases).map(|v| v.to_array());
        let got2 = p2.get(bases).map(|v| v.to_array());
        for j in 0..4 {
            let at = bases[j].min(p1.last());
            let want = [at, at + 1, at + 18, at + 19].map(|k| a[k] as i32);
            assert_eq!(got.map(|v| v[j]), want, "{i} {j}");
            let at = bases[j].min(p2.last());
            let want = [at, at + 1, at + 7, at + 8].map(c2);
            assert_eq!(got2.map(|v| v[j]), want, "{i} {j}");
        }
    }
    assert!(crate::CodePairs::<1>::new(&a[..19], 18).is_none());
    assert!(crate::CodePairs::<1>::new(&a[..20], 18).is_some());
    assert!(crate::CodePairs::<2>::new(&a[..17], 7).is_none());
    assert!(crate::CodePairs::<2>::new(&a[..18], 7).is_some());
    assert!(crate::CodePairs::<3>::new(&a, 1).is_none());
    assert!(crate::CodePairs::<1>::new(&a, usize::MAX).is_none());
}
