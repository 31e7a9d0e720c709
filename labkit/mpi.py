"""mpirun as the grader, the tools and the tests start an MPI lab (lab 04)."""
from __future__ import annotations


def mpirun(ranks: int, distribution: str | None = None, *env: str) -> list[str]:
    """The launcher for MPI labs, RT_MPI_DISTRIBUTION set for every rank when `distribution`
    is given and each NAME=VALUE of `env` too (the sandbox passes none of the grader's
    environment on). Not -q: it would hide OpenMPI's own error text (MPI_ERR_TRUNCATE, a
    rank that died), the cause a student needs; a run that succeeds prints no banner."""
    cmd = ["mpirun", "--oversubscribe", "--bind-to", "none", "-np", str(ranks)]
    for setting in ([f"RT_MPI_DISTRIBUTION={distribution}"] if distribution else []) + list(env):
        cmd += ["-x", setting]
    return cmd
