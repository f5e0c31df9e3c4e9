"""A parameter sweep of the lily on Dask distributed (issue 41).

    python docs/python/sweep.py local [MEMBERS] [KEYFRAMES]   # a LocalCluster here
    python docs/python/sweep.py slurm [MEMBERS] [KEYFRAMES]   # a Slurm cluster

Each member is the lily with its petals' growth rate `dg` and the strength
of its painted e-growth map varied; every member runs on some worker, and
the sweep collects every member as a result or as a failure with its
error. The engine is deterministic: a member's keyframes are the same bits
on any worker, and the same as `anthesis.sweep.run_serial` gives.

On Slurm (pip install dask-jobqueue; the workers' Python needs the anthesis
wheel installed, e.g. in a shared venv):

    from dask_jobqueue import SLURMCluster
    cluster = SLURMCluster(cores=4, processes=1, memory="8GB",
                           walltime="01:00:00", python="/shared/venv/bin/python")
    cluster.scale(jobs=50)

On Kubernetes (pip install dask-kubernetes; an image with the wheel):

    from dask_kubernetes.operator import KubeCluster
    cluster = KubeCluster(name="anthesis", image="registry.example/anthesis-worker:0.1",
                          n_workers=20)

Then the same two lines as below: `Client(cluster)` and `run_on_dask`.
"""

import sys

import numpy as np

import anthesis
from anthesis.sweep import Member, run_on_dask


def members(count: int, keyframes: int) -> list[Member]:
    lily = anthesis.load("builtin:lily")
    key = len(lily.map_keys("petal")) - 1
    painted = lily.get_map("petal", "e_growth", key=key)
    rng = np.random.default_rng(41)  # a fixed seed: the same sweep every time
    out = []
    for i in range(count):
        dg = float(rng.uniform(0.002, 0.004))
        strength = float(rng.uniform(0.8, 1.2))
        out.append(Member(
            name=f"lily-{i:03d}",
            source="builtin:lily",
            parameters={("petal", "dg"): dg},
            maps={("petal", "e_growth"): np.clip(painted * strength, 0, 1)},
            keyframes=keyframes,
        ))
    return out


def main() -> None:
    where = sys.argv[1] if len(sys.argv) > 1 else "local"
    count = int(sys.argv[2]) if len(sys.argv) > 2 else 8
    keyframes = int(sys.argv[3]) if len(sys.argv) > 3 else 20
    from distributed import Client, LocalCluster

    if where == "slurm":
        from dask_jobqueue import SLURMCluster

        cluster = SLURMCluster(cores=4, processes=1, memory="8GB", walltime="01:00:00")
        cluster.scale(jobs=min(count, 50))
    else:
        cluster = LocalCluster(n_workers=2, threads_per_worker=1)
    with cluster, Client(cluster) as client:
        sweep = run_on_dask(client, members(count, keyframes), retries=1)
    print(f"{len(sweep.results)} results, {len(sweep.failures)} failures")
    for name, result in sorted(sweep.results.items()):
        tip = result.positions["petal-1"][:, :, 1].argmax(axis=1)[0]
        end = result.positions["petal-1"][-1, tip]
        print(f"{name}: petal-1 tip at {np.round(end, 3)}, energy {result.energy[-1]:.4g}")
    for name, error in sorted(sweep.failures.items()):
        print(f"{name} FAILED:\n{error}")


if __name__ == "__main__":
    main()
