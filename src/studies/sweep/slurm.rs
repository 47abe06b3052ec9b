//! Slurm job scripts for a sweep: a job array with one task per shard, and a merge job.

use std::path::Path;

/// The options of `magsep sweep slurm`.
#[derive(Debug, Clone, Default)]
pub struct SlurmOptions {
    /// Number of shards (array tasks).
    pub shards: usize,
    /// `#SBATCH --partition`.
    pub partition: Option<String>,
    /// `#SBATCH --time` (Slurm's formats, e.g. `01:00:00` or `2-00:00:00`).
    pub time: Option<String>,
    /// `#SBATCH --cpus-per-task`; each task runs this many points at once (`--jobs`).
    pub cpus_per_task: usize,
    /// Pass `--record` to the shards.
    pub record: bool,
}

/// `s` quoted for a POSIX shell.
pub fn shell_quote(s: &str) -> String {
    format!("'{}'", s.replace('\'', "'\\''"))
}

/// Check a value written into an `#SBATCH` line: letters, digits and `-_:.,+` only.
///
/// # Errors
/// What is wrong, naming the option.
pub fn check_word(flag: &str, value: &str) -> Result<(), String> {
    let ok = !value.is_empty()
        && value
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || "-_:.,+".contains(c));
    if ok {
        Ok(())
    } else {
        Err(format!(
            "{flag} must be non-empty letters, digits and -_:.,+ only, got `{value}`"
        ))
    }
}

fn header(name: &str, log: &Path, o: &SlurmOptions) -> String {
    let mut s = format!(
        "#!/bin/bash\n#SBATCH --job-name={name}\n#SBATCH --output={}\n",
        log.display()
    );
    if let Some(p) = &o.partition {
        s += &format!("#SBATCH --partition={p}\n");
    }
    if let Some(t) = &o.time {
        s += &format!("#SBATCH --time={t}\n");
    }
    s
}

/// `sweep.sbatch`: array tasks 1..=N, task I running `magsep sweep SWEEP --out DIR --shard
/// I/N` with the given binary (all paths absolute).
pub fn array_script(exe: &Path, sweep: &Path, out: &Path, o: &SlurmOptions) -> String {
    let n = o.shards;
    let mut s = header("magsep-sweep", &out.join("slurm").join("shard-%a.out"), o);
    s += &format!(
        "#SBATCH --array=1-{n}\n#SBATCH --cpus-per-task={}\n",
        o.cpus_per_task
    );
    s += "set -euo pipefail\n";
    s += &format!(
        "exec {} sweep {} --out {} --shard \"${{SLURM_ARRAY_TASK_ID}}/{n}\" \
         --jobs \"${{SLURM_CPUS_PER_TASK:-{}}}\" --quiet{}\n",
        shell_quote(&exe.display().to_string()),
        shell_quote(&sweep.display().to_string()),
        shell_quote(&out.display().to_string()),
        o.cpus_per_task,
        if o.record { " --record" } else { "" }
    );
    s
}

/// `merge.sbatch`: `magsep sweep merge DIR` (to be submitted with
/// `--dependency=afterany:<array job id>`).
pub fn merge_script(exe: &Path, out: &Path, o: &SlurmOptions) -> String {
    let mut s = header("magsep-merge", &out.join("slurm").join("merge.out"), o);
    s += "#SBATCH --cpus-per-task=1\nset -euo pipefail\n";
    s += &format!(
        "exec {} sweep merge {}\n",
        shell_quote(&exe.display().to_string()),
        shell_quote(&out.display().to_string())
    );
    s
}

/// `submit.sh`: submits the array, then the merge job depending on it (`afterany`: it runs
/// even when some tasks failed, and reports what is missing).
pub fn submit_script(out: &Path) -> String {
    let q = |name: &str| shell_quote(&out.join(name).display().to_string());
    format!(
        "#!/bin/sh\nset -eu\njob=$(sbatch --parsable {})\njob=${{job%%;*}}\n\
         sbatch --dependency=afterany:\"$job\" {}\necho \"array job $job\"\n",
        q("sweep.sbatch"),
        q("merge.sbatch")
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quoting_survives_quotes() {
        assert_eq!(shell_quote("a b"), "'a b'");
        assert_eq!(shell_quote("it's"), "'it'\\''s'");
        assert!(check_word("--time", "01:00:00").is_ok());
        assert!(check_word("--time", "1\n#SBATCH --x").is_err());
        assert!(check_word("--partition", "").is_err());
    }
}
