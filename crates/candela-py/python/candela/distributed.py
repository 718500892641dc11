"""Renders one frame as Ray tasks, each a range of sample indices, merged exactly.

    python -m candela.distributed SCENE --spp N --chunks K -o out.exr [--address ADDR]

Each chunk is a Ray task that loads the scene, renders its samples ``range(a, b)`` and
returns its :class:`candela.Film` (exact per-pixel sums, sent through Ray's object
store); the driver merges them into bit for bit the single-process render of
``range(N)``. A task whose worker dies is retried (``--max-retries``) and, since a range
renders to the same bits wherever it runs, the result stays exact.

Scene files: the workers read the scene from **shared storage** at the same absolute
path as the driver (one machine, or a cluster whose nodes mount the same file system);
``--ship`` instead uploads the scene file's folder to the cluster with Ray's
``runtime_env`` ``working_dir`` (up to Ray's upload limit) and the workers read it there.

Without ``--address`` Ray starts locally (``--workers`` CPUs, default all); with
``--address ray://HOST:10001`` or ``auto`` it joins a running cluster, whose nodes each
need this package installed (``pip install candela[ray]``).
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from typing import Dict, List, Optional, Sequence, Tuple

import candela


def chunk_ranges(spp: int, chunks: int) -> List[range]:
    """Splits ``range(spp)`` into ``chunks`` contiguous ranges of near-equal length."""
    if not 1 <= chunks <= spp:
        raise ValueError(f"chunks must lie in 1..{spp} (the spp), got {chunks}")
    bounds = [spp * i // chunks for i in range(chunks + 1)]
    return [range(a, b) for a, b in zip(bounds, bounds[1:])]


def _render_chunk(
    path: str,
    params: Dict[str, str],
    spp: int,
    seed: Optional[int],
    start: int,
    stop: int,
    threads: Optional[int],
    task_log: Optional[str],
) -> candela.Film:
    """The body of one Ray task."""
    if task_log:
        # One file per attempt, so that monitors (and the tests) see retries.
        name = f"{start}-{stop}.{os.getpid()}.{time.monotonic_ns()}"
        with open(os.path.join(task_log, name), "w") as f:
            f.write(f"{os.getpid()} {start} {stop}\n")
    scene = candela.load(path, **params)
    return candela.render(scene, spp=spp, seed=seed, threads=threads, samples=range(start, stop))


def render_distributed(
    path: str,
    spp: Optional[int] = None,
    chunks: int = 4,
    seed: Optional[int] = None,
    params: Optional[Dict[str, str]] = None,
    threads_per_task: int = 1,
    max_retries: int = 3,
    ship: bool = False,
    task_log: Optional[str] = None,
) -> candela.Film:
    """Renders ``range(spp)`` of the scene at ``path`` as ``chunks`` Ray tasks of
    ``threads_per_task`` threads each (one Ray CPU each) and returns the merged film.

    Ray must be initialised (``ray.init``) by the caller; :func:`main` does it. With
    ``ship=True`` the caller's ``ray.init`` must carry ``runtime_env={"working_dir":
    folder of the scene}`` and ``path`` be relative to that folder.
    """
    import ray

    params = dict(params or {})
    scene = candela.load(path, **params)
    spp = spp if spp is not None else scene.spp
    if not ship:
        path = os.path.abspath(path)
    task = ray.remote(num_cpus=threads_per_task, max_retries=max_retries)(_render_chunk)
    refs = [
        task.remote(path, params, spp, seed, r.start, r.stop, threads_per_task, task_log)
        for r in chunk_ranges(spp, chunks)
    ]
    return candela.merge(ray.get(refs))


def _parse_define(s: str) -> Tuple[str, str]:
    if "=" not in s:
        raise argparse.ArgumentTypeError(f'expected NAME=VALUE, got "{s}"')
    k, v = s.split("=", 1)
    return k.strip(), v


def main(argv: Optional[Sequence[str]] = None) -> int:
    ap = argparse.ArgumentParser(
        prog="python -m candela.distributed",
        description="Render a frame as Ray tasks of sample ranges, merged bit for bit.",
    )
    ap.add_argument("scene", help="scene file (.toml, Mitsuba .xml, .gltf/.glb)")
    ap.add_argument("-o", "--output", required=True, help=".exr (a mergeable film), .pfm or .png")
    ap.add_argument("--spp", type=int, help="samples per pixel (default: the scene's)")
    ap.add_argument("--seed", type=int, help="seed (default: the scene's)")
    ap.add_argument("--chunks", type=int, default=4, help="Ray tasks, each a sample range")
    ap.add_argument("-D", dest="define", action="append", type=_parse_define, default=[],
                    metavar="NAME=VALUE", help="scene parameter")
    ap.add_argument("--address", help="Ray cluster (ray://HOST:10001 or auto); default: local")
    ap.add_argument("--workers", type=int, help="CPUs of a local Ray (default: all)")
    ap.add_argument("--threads-per-task", type=int, default=1,
                    help="render threads (and Ray CPUs) per task")
    ap.add_argument("--max-retries", type=int, default=3,
                    help="retries of a task whose worker died")
    ap.add_argument("--ship", action="store_true",
                    help="upload the scene's folder to the workers instead of shared storage")
    ap.add_argument("--task-log", metavar="DIR",
                    help="each task attempt writes a file here (pid and range)")
    ap.add_argument("--exposure", type=float, default=0.0, help="PNG: stops")
    ap.add_argument("--tonemap", default="none", help="PNG: tone curve")
    args = ap.parse_args(argv)

    import ray

    path = args.scene
    out = os.path.abspath(args.output)
    init: Dict[str, object] = {"address": args.address} if args.address else {}
    if args.workers and not args.address:
        init["num_cpus"] = args.workers
    if args.ship:
        folder = os.path.dirname(os.path.abspath(path))
        init["runtime_env"] = {"working_dir": folder}
        path = os.path.basename(path)
        os.chdir(folder)
    ray.init(**init)
    start = time.monotonic()
    try:
        film = render_distributed(
            path,
            spp=args.spp,
            chunks=args.chunks,
            seed=args.seed,
            params=dict(args.define),
            threads_per_task=args.threads_per_task,
            max_retries=args.max_retries,
            ship=args.ship,
            task_log=args.task_log,
        )
    except (candela.SceneError, candela.MergeError, ValueError) as e:
        print(f"candela.distributed: {e}", file=sys.stderr)
        return 2
    finally:
        elapsed = time.monotonic() - start
    candela.write(out, film, exposure=args.exposure, tonemap=args.tonemap)
    print(f"{film.width}x{film.height}, {film.spp} spp in {args.chunks} chunks, "
          f"{elapsed:.2f} s -> {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
