"""The process and socket tables as the sweep tests read them, through psutil: no `pgrep` or `ss`,
which slim container images (python:3.13-slim) do not have."""
import os

import psutil

RAY_MARKS = ("raylet", "gcs_server", "ray::")  # Ray's services, and its workers' process titles
LOOPBACK = {"127.0.0.1", "::1", "::ffff:127.0.0.1"}


def ray_pids() -> set[int]:
    """Every process of a local Ray on this machine: its services and its workers."""
    found = set()
    for proc in psutil.process_iter(["name", "cmdline"]):
        title = " ".join([proc.info["name"] or "", *(proc.info["cmdline"] or [])])
        if any(mark in title for mark in RAY_MARKS):
            found.add(proc.pid)
    return found


def own_ray_processes() -> list[psutil.Process]:
    """The Ray processes this process started (its descendants): not those of a Ray that another
    process runs meanwhile (a sweep of another test worker, a user's own)."""
    ray = ray_pids()
    return [child for child in psutil.Process().children(recursive=True) if child.pid in ray]


def alive(processes: list[psutil.Process]) -> list[int]:
    """The pids of ``processes`` still running (a zombie, dead but not yet reaped, is not)."""
    running = []
    for proc in processes:
        try:
            if proc.is_running() and proc.status() != psutil.STATUS_ZOMBIE:
                running.append(proc.pid)
        except psutil.NoSuchProcess:
            pass
    return running


def group_pids(pgid: int) -> set[int]:
    """The processes of a process group (a command started with ``start_new_session``)."""
    found = set()
    for proc in psutil.process_iter():
        try:
            if os.getpgid(proc.pid) == pgid:
                found.add(proc.pid)
        except ProcessLookupError:
            pass
    return found


def listening(pids: set[int]) -> list[tuple[int, str, int]]:
    """(pid, address, port) of each TCP socket that one of ``pids`` listens on."""
    return [(c.pid, c.laddr.ip, c.laddr.port) for c in psutil.net_connections(kind="tcp")
            if c.status == psutil.CONN_LISTEN and c.pid in pids]


def outside_loopback(sockets: list[tuple[int, str, int]]) -> list[tuple[int, str, int]]:
    return [s for s in sockets if s[1] not in LOOPBACK]
