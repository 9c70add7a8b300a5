"""Throughput of planning many tasks: 1,000 generated reach tasks (a grid of
wrist targets around an obstacle, on two robots), planned by ``a2ml.plan_many``
on 1 and 2 threads, by ``a2ml plan`` on a folder (peak memory against the
number of tasks), and through Dask with 2 worker processes.

    python benches/many_tasks.py [--tasks 1000] [--cli target/release/a2ml]

Run it in the venv of ``make python``. It prints one line per measurement;
the README quotes them with the machine they ran on.
"""

from __future__ import annotations

import argparse
import itertools
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import a2ml

ROOT = Path(__file__).resolve().parent.parent

# Each robot: its URDF, a start (deg) and the obstacle's offset from the start's wrist (m).
ROBOTS = {
    "coman": ("robots/coman_right_arm.urdf", [0, -20, 0, -60, 0, 10, 0], [0.0, -0.10, -0.06]),
    "iiwa14": ("robots/iiwa14.urdf", [0, 70, 0, -70, 0, -40, 0], [0.0, 0.10, -0.10]),
}


def base_task(name: str) -> tuple[a2ml.Task, np.ndarray]:
    """A reach of `name` from its start to a placeholder goal, a sphere beside the way,
    and the start's wrist position."""
    urdf, start, offset = ROBOTS[name]
    robot = a2ml.Robot.from_urdf(ROOT / urdf)
    pw, _, _ = robot.cpsa(np.radians(start))
    centre = pw + np.array(offset)
    text = (
        f'robot "{ROOT / urdf}"\n'
        f"start [{', '.join(map(str, start))}] deg\n"
        f"scene {{ ball = sphere at [{', '.join(f'{c:.6f}' for c in centre)}] radius 3 cm }}\n"
        f"task reach_{name} {{ action reach {{ goal Pw = [{', '.join(f'{c:.6f}' for c in pw)}] }} }}\n"
    )
    return a2ml.parse(text), pw


def generated(count: int) -> list[a2ml.Task]:
    """`count` reach tasks, half per robot: targets on a grid of 2 cm steps around each
    start's wrist, the obstacle between some of them and the start."""
    tasks: list[a2ml.Task] = []
    per_robot = count // len(ROBOTS)
    for name in ROBOTS:
        task, pw = base_task(name)
        steps = [-0.06, -0.04, -0.02, 0.02, 0.04, 0.06, 0.08, 0.10, -0.08, 0.0]
        grid = itertools.product(steps, steps, steps)
        for offset in itertools.islice(grid, per_robot):
            tasks.append(task.with_goal("reach", pw=pw + np.array(offset)))
    return tasks


def peak_rss_mb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


def throughput(tasks: list[a2ml.Task], jobs: int) -> float:
    started = time.perf_counter()
    results = a2ml.plan_many(tasks, jobs=jobs)
    seconds = time.perf_counter() - started
    planned = sum(isinstance(r, a2ml.Plan) for r in results)
    print(f"plan_many jobs={jobs}: {len(tasks)} tasks ({planned} planned) in {seconds:.1f} s, "
          f"{len(tasks) / seconds:.1f} tasks/s")
    return seconds


def cli_memory(cli: str, tasks: list[a2ml.Task], counts: list[int]) -> None:
    """Peak resident memory of `a2ml plan FOLDER --parquet` against the number of tasks."""
    for count in counts:
        with tempfile.TemporaryDirectory() as folder:
            tasks_dir, out = Path(folder, "tasks"), Path(folder, "out")
            tasks_dir.mkdir()
            out.mkdir()
            for i, task in enumerate(tasks[:count]):
                (tasks_dir / f"t{i:05}.a2ml").write_text(task.source)
            command = ["/usr/bin/time", "-f", "%M %e", cli, "plan", str(tasks_dir),
                       "--parquet", str(out / "{stem}.parquet"), "--jobs", "2"]
            done = subprocess.run(command, capture_output=True, text=True)
            kb, seconds = done.stderr.strip().splitlines()[-1].split()
            print(f"a2ml plan --jobs 2: {count} tasks in {float(seconds):.1f} s, "
                  f"peak RSS {int(kb) / 1024:.0f} MB (exit {done.returncode})")


def dask_throughput(tasks: list[a2ml.Task]) -> None:
    from dask.distributed import Client, LocalCluster

    import a2ml.dask

    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                      dashboard_address=None) as cluster, Client(cluster) as client:
        started = time.perf_counter()
        results = client.compute(a2ml.dask.plan_bag(tasks, npartitions=16)).result()
        seconds = time.perf_counter() - started
    planned = sum(isinstance(r, a2ml.Plan) for r in results)
    print(f"dask 2 workers: {len(tasks)} tasks ({planned} planned) in {seconds:.1f} s, "
          f"{len(tasks) / seconds:.1f} tasks/s")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--tasks", type=int, default=1000)
    parser.add_argument("--cli", default=str(ROOT / "target" / "release" / "a2ml"))
    args = parser.parse_args()
    tasks = generated(args.tasks)
    print(f"{len(tasks)} tasks on {len(ROBOTS)} robots, {os.cpu_count()} cores, "
          f"load average {os.getloadavg()[0]:.1f}")
    one = throughput(tasks, 1)
    two = throughput(tasks, 2)
    print(f"speed-up on 2 threads: {one / two:.2f}; peak RSS of this process {peak_rss_mb():.0f} MB")
    if Path(args.cli).exists():
        cli_memory(args.cli, tasks, [args.tasks // 4, args.tasks])
    else:
        print(f"no CLI at {args.cli}: peak memory not measured", file=sys.stderr)
    dask_throughput(tasks)


if __name__ == "__main__":
    main()
