"""CPU time of a child process, for the benchmark scripts (bench/compare_commit.py, bench/simbody/compare.py)."""
import resource
import subprocess


def run_timed(command, env=None):
    """Runs command (a list; env: its environment, None for this one's); returns (CPU seconds, user + system, of that process; its CompletedProcess).

    The kernel's accounting of the child: other work on the machine does not inflate it the
    way it inflates wall time. Raises RuntimeError naming the command when it fails."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    finished = subprocess.run(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if finished.returncode != 0:
        raise RuntimeError(f"{' '.join(command)} failed ({finished.returncode}): {finished.stderr.strip()}")
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime), finished
