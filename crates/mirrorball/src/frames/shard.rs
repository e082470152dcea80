//! `--shard i/n`: slice `i` of `n` equal, contiguous slices, `i` counted from 0 (as Slurm
//! array indices given `--array=0-(n-1)` and Kubernetes' `JOB_COMPLETION_INDEX` count).
//! Contiguous, so that a video's frames stay in order on each machine; slice `i` of `len`
//! items is `[i·len/n, (i+1)·len/n)`, so the slices differ in length by at most one and
//! together hold every item once.

use crate::error::Error;
use std::ops::Range;

/// A slice of work: `index` of `count`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shard {
    pub index: u64,
    pub count: u64,
}

impl Shard {
    /// Parses `I/N`.
    pub fn parse(s: &str) -> Result<Shard, Error> {
        let bad = |why: String| Error::request(format!("--shard {s}: {why}"));
        let (i, n) = s
            .split_once('/')
            .ok_or_else(|| bad("not I/N (slice I of N, I from 0 to N-1)".into()))?;
        let num = |t: &str| {
            t.trim()
                .parse::<u64>()
                .map_err(|_| bad(format!("'{t}' is not a whole number")))
        };
        let (index, count) = (num(i)?, num(n)?);
        if count == 0 {
            return Err(bad("the number of slices must be at least 1".into()));
        }
        if index >= count {
            return Err(bad(format!(
                "slices are counted from 0, so I is 0..={} for {count} slices",
                count - 1
            )));
        }
        Ok(Shard { index, count })
    }

    /// The items of this slice of `len` items.
    pub fn range(self, len: usize) -> Range<usize> {
        let at = |k: u64| (k as u128 * len as u128 / self.count as u128) as usize;
        at(self.index)..at(self.index + 1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slices_cover_every_item_once() {
        for len in [0usize, 1, 7, 100, 101] {
            for count in [1u64, 2, 3, 8, 150] {
                let mut seen = vec![0; len];
                for index in 0..count {
                    let r = Shard { index, count }.range(len);
                    assert!(r.len() <= len / count as usize + 1);
                    r.for_each(|k| seen[k] += 1);
                }
                assert!(seen.iter().all(|&s| s == 1), "{len} in {count}");
            }
        }
    }

    #[test]
    fn bad_shards_are_refused_with_the_rule() {
        assert_eq!(Shard::parse("3/8").unwrap(), Shard { index: 3, count: 8 });
        for (s, says) in [
            ("3/2", "0..=1 for 2 slices"),
            ("2/2", "counted from 0"),
            ("0/0", "at least 1"),
            ("1", "not I/N"),
            ("a/2", "'a' is not"),
            ("-1/2", "'-1' is not"),
        ] {
            let e = Shard::parse(s).unwrap_err();
            assert!(e.message.contains(says), "{s}: {}", e.message);
            assert_eq!(e.fault, mirrorball_core::Fault::Request);
        }
    }
}
