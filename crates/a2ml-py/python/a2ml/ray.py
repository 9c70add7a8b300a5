"""Planning a batch on Ray: :func:`plan_remote`.

The robot is put in Ray's object store once (``ray.put``) and the tasks are
split into chunks, each planned by one remote call of :func:`a2ml.plan_many`
(robots loaded once per chunk, plans made without the GIL). Plans come back as
pickles, failures as exception values in their task's place, in input order::

    import ray, a2ml, a2ml.ray

    ray.init(num_cpus=2)
    plans = a2ml.ray.plan_remote(tasks, robot=robot)

Ray must be initialised (``ray.init``) by the caller, as for any remote call.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from typing import Any

import ray

from a2ml._a2ml import Plan, Robot, Task, plan_many

__all__ = ["plan_remote"]


@ray.remote
def _plan_chunk(
    tasks: list[Task | str | os.PathLike[str]],
    robot: Robot | None,
    options: dict[str, Any],
) -> list[Plan | Exception]:
    return plan_many(tasks, robot=robot, **options)


def plan_remote(
    tasks: Sequence[Task | str | os.PathLike[str]],
    robot: Robot | None = None,
    *,
    chunks: int | None = None,
    **options: Any,
) -> list[Plan | Exception]:
    """The plans of ``tasks`` (Tasks or paths), each a :class:`a2ml.Plan` or the
    exception :func:`a2ml.plan` would have raised, in input order.

    ``chunks`` defaults to four per CPU of the Ray cluster; ``options`` are
    :func:`a2ml.plan_many`'s, with ``jobs`` the planning threads per chunk,
    default 1.
    """
    items = list(tasks)
    if not items:
        return []
    options.setdefault("jobs", 1)
    cpus = ray.cluster_resources().get("CPU", 1)  # type: ignore[no-untyped-call]
    count = chunks or 4 * max(1, int(cpus))
    size = -(-len(items) // max(1, min(count, len(items))))
    shared = ray.put(robot)
    refs = [
        _plan_chunk.remote(items[i : i + size], shared, options)
        for i in range(0, len(items), size)
    ]
    return [plan for chunk in ray.get(refs) for plan in chunk]
