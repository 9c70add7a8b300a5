"""Planning a batch on a Dask cluster: :func:`plan_bag`.

The tasks become a ``dask.bag`` whose partitions each go through
:func:`a2ml.plan_many` on a worker, so a partition's robots are loaded once and
its plans made without the GIL. A robot passed in is one object of the graph,
sent once to each worker that needs it, not once per task. Plans come back as
pickles (a :class:`a2ml.Plan` pickles as its data, with its robot and task),
failures as exception values in their task's place, in input order::

    from dask.distributed import Client
    import a2ml, a2ml.dask

    client = Client(n_workers=2, threads_per_worker=1)
    tasks = [base.with_goal("reach", pw=p) for p in targets]
    plans = a2ml.dask.plan_bag(tasks, robot=robot).compute()

To keep large results off the client, write them on the workers instead:
``plan_bag(...).map(lambda p: p.to_parquet(...))``.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from typing import Any

import dask.bag
from dask.delayed import delayed

from a2ml._a2ml import Plan, Robot, Task, plan_many

__all__ = ["plan_bag"]


def _plan_partition(
    tasks: list[Task | str | os.PathLike[str]],
    robot: Robot | None,
    options: dict[str, Any],
) -> list[Plan | Exception]:
    return plan_many(tasks, robot=robot, **options)


def plan_bag(
    tasks: Sequence[Task | str | os.PathLike[str]],
    robot: Robot | None = None,
    *,
    npartitions: int | None = None,
    **options: Any,
) -> dask.bag.Bag:
    """A bag of the plans of ``tasks`` (Tasks or paths), each a :class:`a2ml.Plan`
    or the exception :func:`a2ml.plan` would have raised, in input order.

    ``npartitions`` defaults to dask's choice for the sequence (at most 100);
    ``options`` are :func:`a2ml.plan_many`'s (``solver``, ``rate``, ``seed``,
    ...), with ``jobs`` the planning threads per partition, default 1: the
    workers' threads already run partitions in parallel. Nothing runs until
    the bag is computed.
    """
    options.setdefault("jobs", 1)
    # dask.bag's functions are untyped.
    bag: dask.bag.Bag = dask.bag.from_sequence(  # type: ignore[no-untyped-call]
        list(tasks), npartitions=npartitions
    )
    # One key in the graph: the robot travels once per worker, not with every partition.
    shared = delayed(robot) if robot is not None else None
    planned: dask.bag.Bag = bag.map_partitions(  # type: ignore[no-untyped-call]
        _plan_partition, shared, options
    )
    return planned
