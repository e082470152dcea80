//! Deterministic mutations of seed files, shared by the io, render and CLI test binaries
//! (the others include this file with `#[path]`): cuts, bit flips, inflated size fields,
//! random bytes; and a fuzzer's script applied to a seed.
#![allow(dead_code)]

/// A deterministic xorshift generator.
pub struct Rng(pub u64);
impl Rng {
    pub fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }
    pub fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

/// The size values a hostile header declares: 2³¹, 2³²−1 (as u32) and 2⁴⁰ (as u64).
const INFLATED: [&[u8]; 3] = [
    &0x8000_0000u32.to_le_bytes(),
    &u32::MAX.to_le_bytes(),
    &(1u64 << 40).to_le_bytes(),
];

/// Mutations of `seed`, deterministic for a given `salt`: the seed cut at every `len / 40`
/// bytes, 40 single bit flips, the three [`INFLATED`] values written at 24 places in the
/// first 512 bytes (where the headers are) and 12 anywhere, and 8 runs of random bytes.
pub fn mutations(seed: &[u8], salt: u64) -> Vec<Vec<u8>> {
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15 ^ salt.wrapping_mul(0x2545_f491_4f6c_dd1d) | 1);
    let n = seed.len();
    let mut out = Vec::new();
    for cut in (0..n).step_by((n / 40).max(1)) {
        out.push(seed[..cut].to_vec());
    }
    for _ in 0..40 {
        let mut m = seed.to_vec();
        let at = rng.below(n);
        m[at] ^= 1 << rng.below(8);
        out.push(m);
    }
    for k in 0..36 {
        let span = if k < 24 { n.min(512) } else { n };
        let at = rng.below(span);
        for value in INFLATED {
            let mut m = seed.to_vec();
            let end = (at + value.len()).min(n);
            m[at..end].copy_from_slice(&value[..end - at]);
            out.push(m);
        }
    }
    for _ in 0..8 {
        let mut m = seed.to_vec();
        let at = rng.below(n);
        for b in m.iter_mut().skip(at).take(1 + rng.below(8)) {
            *b = rng.next() as u8;
        }
        out.push(m);
    }
    out
}

/// `seed` changed by a fuzzer's `script`: its first byte picks a cut (255: none, else the
/// length scaled by byte/255), the rest, three bytes at a time, are a position (16 bits,
/// scaled to the file) and a byte to put there; a position whose top bit is set writes
/// one of the [`INFLATED`] sizes instead.
pub fn apply_script(seed: &[u8], script: &[u8]) -> Vec<u8> {
    let mut m = seed.to_vec();
    let Some((&cut, rest)) = script.split_first() else {
        return m;
    };
    for op in rest.chunks_exact(3) {
        if m.is_empty() {
            break;
        }
        let pos = u16::from_le_bytes([op[0], op[1]]);
        let at = (pos & 0x7fff) as usize % m.len();
        if pos & 0x8000 != 0 {
            let value = INFLATED[op[2] as usize % INFLATED.len()];
            let end = (at + value.len()).min(m.len());
            let len = end - at;
            m[at..end].copy_from_slice(&value[..len]);
        } else {
            m[at] = op[2];
        }
    }
    if cut != 255 {
        m.truncate(m.len() * cut as usize / 255);
    }
    m
}
