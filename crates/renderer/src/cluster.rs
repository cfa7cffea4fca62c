//! `--shard auto`: a shard's `K/N` from the cluster scheduler that started the process, so one
//! command line serves every task of a job array (see `docs/cluster.md`).
//!
//! | scheduler | `K` | `N` |
//! |---|---|---|
//! | Slurm job array (`sbatch --array=A-B`) | `SLURM_ARRAY_TASK_ID - SLURM_ARRAY_TASK_MIN` | `SLURM_ARRAY_TASK_COUNT`, else `SLURM_ARRAY_TASK_MAX - SLURM_ARRAY_TASK_MIN + 1` |
//! | Kubernetes Indexed Job | `JOB_COMPLETION_INDEX` | `--shards N` (the Job's `completions`, which Kubernetes does not put in the environment) |
//! | AWS Batch array job | `AWS_BATCH_JOB_ARRAY_INDEX` | `AWS_BATCH_JOB_ARRAY_SIZE` |
//!
//! `--shards N`, when given, must agree with the scheduler's `N` (a typo in one of two places
//! would otherwise leave chunks unrendered). A Slurm array with a step (`--array=0-15:2`) is
//! refused: its task IDs do not number the shards `0..N`. Exactly one scheduler's variables
//! may be set.

/// Reads `K/N` for `--shard auto` from the environment through `get` (`std::env::var` in the
/// binary; a map in tests), with `--shards N` as `shards`.
///
/// # Errors
/// What is missing or inconsistent, naming the variables.
pub fn shard_from_environment(
    get: impl Fn(&str) -> Option<String>,
    shards: Option<u64>,
) -> Result<(u64, u64), String> {
    let number = |name: &str| -> Result<Option<u64>, String> {
        match get(name) {
            None => Ok(None),
            Some(v) => v.trim().parse::<u64>().map(Some).map_err(|_| {
                format!("--shard auto: {name}={v:?} is not a whole number from 0 to {}", u64::MAX)
            }),
        }
    };
    let slurm = number("SLURM_ARRAY_TASK_ID")?;
    let kubernetes = number("JOB_COMPLETION_INDEX")?;
    let aws = number("AWS_BATCH_JOB_ARRAY_INDEX")?;
    let found = [slurm.is_some(), kubernetes.is_some(), aws.is_some()];
    let (k, n, scheduler) = match found {
        [true, false, false] => {
            let id = slurm.unwrap_or_default();
            let min = number("SLURM_ARRAY_TASK_MIN")?.ok_or_else(|| {
                "--shard auto: SLURM_ARRAY_TASK_ID is set but SLURM_ARRAY_TASK_MIN is not (is \
                 this a job array?)"
                    .to_owned()
            })?;
            if let Some(step) = number("SLURM_ARRAY_TASK_STEP")?
                && step != 1
            {
                return Err(format!(
                    "--shard auto: the Slurm array steps by {step} (SLURM_ARRAY_TASK_STEP): its \
                     task IDs do not number the shards 0..N; submit it as --array=0-{{N-1}}"
                ));
            }
            let n = match (number("SLURM_ARRAY_TASK_COUNT")?, number("SLURM_ARRAY_TASK_MAX")?) {
                (Some(count), _) => count,
                (None, Some(max)) if max >= min => max - min + 1,
                _ => {
                    return Err("--shard auto: neither SLURM_ARRAY_TASK_COUNT nor a \
                                SLURM_ARRAY_TASK_MAX at or above SLURM_ARRAY_TASK_MIN is set"
                        .to_owned());
                }
            };
            let k = id.checked_sub(min).ok_or_else(|| {
                format!(
                    "--shard auto: SLURM_ARRAY_TASK_ID={id} is below SLURM_ARRAY_TASK_MIN={min}"
                )
            })?;
            (k, n, "Slurm")
        }
        [false, true, false] => {
            let n = shards.ok_or_else(|| {
                "--shard auto: Kubernetes sets JOB_COMPLETION_INDEX but not the number of \
                 completions: pass --shards N (the Job's spec.completions)"
                    .to_owned()
            })?;
            (kubernetes.unwrap_or_default(), n, "Kubernetes")
        }
        [false, false, true] => {
            let n = number("AWS_BATCH_JOB_ARRAY_SIZE")?.ok_or_else(|| {
                "--shard auto: AWS_BATCH_JOB_ARRAY_INDEX is set but AWS_BATCH_JOB_ARRAY_SIZE is \
                 not"
                .to_owned()
            })?;
            (aws.unwrap_or_default(), n, "AWS Batch")
        }
        [false, false, false] => {
            return Err("--shard auto: no scheduler's array index in the environment (looked for \
                        SLURM_ARRAY_TASK_ID, JOB_COMPLETION_INDEX and AWS_BATCH_JOB_ARRAY_INDEX); \
                        give --shard K/N"
                .to_owned());
        }
        _ => {
            return Err("--shard auto: more than one scheduler's array index is set \
                        (SLURM_ARRAY_TASK_ID, JOB_COMPLETION_INDEX, AWS_BATCH_JOB_ARRAY_INDEX); \
                        give --shard K/N"
                .to_owned());
        }
    };
    if let Some(s) = shards
        && s != n
    {
        return Err(format!("--shard auto: --shards {s} but the {scheduler} array has {n} tasks"));
    }
    if n == 0 || k >= n {
        return Err(format!(
            "--shard auto: task {k} of {n} from the {scheduler} environment: need 0 <= K < N"
        ));
    }
    Ok((k, n))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn with<'a>(vars: &'a [(&'a str, &'a str)]) -> impl Fn(&str) -> Option<String> + 'a {
        move |name| vars.iter().find(|(k, _)| *k == name).map(|(_, v)| (*v).to_owned())
    }

    #[test]
    fn slurm_arrays_number_their_tasks_from_their_minimum() {
        let a = [
            ("SLURM_ARRAY_TASK_ID", "5"),
            ("SLURM_ARRAY_TASK_MIN", "1"),
            ("SLURM_ARRAY_TASK_MAX", "8"),
        ];
        assert_eq!(shard_from_environment(with(&a), None), Ok((4, 8)));
        let mut b = a.to_vec();
        b.push(("SLURM_ARRAY_TASK_COUNT", "8"));
        assert_eq!(shard_from_environment(with(&b), Some(8)), Ok((4, 8)));
        let e = shard_from_environment(with(&b), Some(7)).unwrap_err();
        assert!(e.contains("--shards 7") && e.contains("8 tasks"), "{e}");
        let mut c = a.to_vec();
        c.push(("SLURM_ARRAY_TASK_STEP", "2"));
        assert!(shard_from_environment(with(&c), None).unwrap_err().contains("steps by 2"));
        let d = [("SLURM_ARRAY_TASK_ID", "5")];
        assert!(shard_from_environment(with(&d), None).unwrap_err().contains("TASK_MIN"));
        let e = [("SLURM_ARRAY_TASK_ID", "x"), ("SLURM_ARRAY_TASK_MIN", "0")];
        let e = shard_from_environment(with(&e), None).unwrap_err();
        assert!(e.contains("SLURM_ARRAY_TASK_ID=\"x\""), "{e}");
    }

    #[test]
    fn kubernetes_needs_the_completions_and_aws_gives_its_size() {
        let k = [("JOB_COMPLETION_INDEX", "3")];
        assert_eq!(shard_from_environment(with(&k), Some(4)), Ok((3, 4)));
        assert!(shard_from_environment(with(&k), None).unwrap_err().contains("--shards N"));
        assert!(shard_from_environment(with(&k), Some(3)).unwrap_err().contains("0 <= K < N"));
        let a = [("AWS_BATCH_JOB_ARRAY_INDEX", "0"), ("AWS_BATCH_JOB_ARRAY_SIZE", "10")];
        assert_eq!(shard_from_environment(with(&a), None), Ok((0, 10)));
        let both = [("AWS_BATCH_JOB_ARRAY_INDEX", "0"), ("JOB_COMPLETION_INDEX", "1")];
        assert!(shard_from_environment(with(&both), Some(2)).unwrap_err().contains("more than"));
        let none: [(&str, &str); 0] = [];
        let e = shard_from_environment(with(&none), None).unwrap_err();
        assert!(e.contains("no scheduler") && e.contains("--shard K/N"), "{e}");
    }
}
