"""A multi-node Ray cluster on one machine, started with the README's commands, for the Ray
fault drill (``scripts/ray_drill.py``) and its test (``tests/grid/test_ray_cluster.py``).

Each node is one ``ray start ... --block`` process in its own session, with its own
``--temp-dir``, ports, CPUs and a custom resource named after it, so that a node can be
killed (SIGKILL to every process of it, as a power cut would) or stopped (SIGTERM: ``ray
start --block`` stops its node) without touching any other Ray on the machine: ``ray stop``
is never used, since it stops every Ray process of the machine, other users' too.

The token: the README's ``ray get-auth-token --generate`` with ``HOME`` pointing at the head's
own home folder (the token lands in ``<head home>/.ray/auth_token``); the head starts with
``RAY_AUTH_MODE=token``; a worker node gets ``RAY_AUTH_MODE=token`` and the token in
``RAY_AUTH_TOKEN`` and a home folder without a token file, as on another machine. A worker
node can run in a private mount namespace where a folder of the driver (the output folders)
is covered by an empty tmpfs (``hide``), so that nothing can reach a run folder through the
file system: run folders travel inside the tasks' arguments and results.
"""

from __future__ import annotations

import contextlib
import os
import re
import shlex
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
BIN = Path(sys.executable).parent

#: The README's cluster block: the lines between these markers are the commands run here.
README_BEGIN = "<!-- cluster: tests/grid/test_ray_cluster.py runs these commands -->"


def readme_commands(readme: Path = ROOT / "README.md") -> list[str]:
    """The shell commands of the README's cluster block (comments and blank lines dropped)."""
    text = readme.read_text()
    start = text.index(README_BEGIN)
    block = text[start:].split("```bash\n", 1)[1].split("```", 1)[0]
    lines = [line.split("  #", 1)[0].strip() for line in block.splitlines()]
    return [line for line in lines if line and not line.startswith("#")]


def free_port_block(size: int = 500) -> int:
    """A base port P such that P..P+size-1 look free (bound by nothing right now)."""
    rng = int.from_bytes(os.urandom(2), "big")
    for attempt in range(50):
        base = 30000 + (rng + attempt * 997) % 25000
        try:
            for port in (base, base + 1, base + 2, base + 3, base + 4):
                with socket.socket() as s:
                    s.bind(("", port))
            return base
        except OSError:
            continue
    raise RuntimeError("no free port block found")


def can_hide() -> bool:
    """Whether ``unshare --mount`` and a tmpfs mount work here (root, or user namespaces)."""
    probe = Path(f"/tmp/.ray_cluster_probe_{os.getpid()}")
    probe.mkdir(exist_ok=True)
    try:
        ok = subprocess.run(
            [*unshare_argv(), "sh", "-c", f"mount -t tmpfs -o size=1m tmpfs {probe}"],
            capture_output=True,
            timeout=20,
        )
        return ok.returncode == 0
    except (OSError, subprocess.TimeoutExpired):
        return False
    finally:
        probe.rmdir()


def unshare_argv() -> list[str]:
    user = [] if os.geteuid() == 0 else ["--user", "--map-root-user"]
    return ["unshare", *user, "--mount", "--propagation", "private"]


def _proc_table() -> dict[int, tuple[int, str]]:
    """pid -> (parent pid, command line) of every process (Linux ``/proc``)."""
    table = {}
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            stat = (entry / "stat").read_text()
            ppid = int(stat.rsplit(")", 1)[1].split()[1])
            cmd = (entry / "cmdline").read_bytes().replace(b"\0", b" ").decode(errors="replace")
        except (OSError, IndexError, ValueError):
            continue
        table[int(entry.name)] = (ppid, cmd.strip())
    return table


def _alive(pid: int) -> bool:
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except (OSError, IndexError):
        return False
    return state != "Z"


def _kill(pids: list[int], sig: int = signal.SIGKILL, wait_s: float = 10.0) -> None:
    for pid in pids:
        with contextlib.suppress(OSError):
            os.kill(pid, sig)
    t0 = time.monotonic()
    while any(_alive(p) for p in pids) and time.monotonic() - t0 < wait_s:
        time.sleep(0.1)


@dataclass
class Node:
    """One ``ray start --block`` process and what it started."""

    name: str
    proc: subprocess.Popen[bytes]
    temp_dir: Path
    log: Path
    seen: set[int] = field(default_factory=set)

    def processes(self) -> dict[int, str]:
        """Every live process of the node (pid -> command line): ``ray start`` and its
        descendants (raylet, GCS, agents, Ray workers), plus any seen before still alive."""
        table = _proc_table()
        found = {self.proc.pid} if self.proc.pid in table else set()
        frontier = set(found)
        while frontier:
            frontier = {pid for pid, (ppid, _) in table.items() if ppid in frontier} - found
            found |= frontier
        found |= {pid for pid in self.seen if pid in table and _alive(pid)}
        self.seen |= found
        return {pid: table[pid][1] for pid in found if _alive(pid)}

    def task_processes(self, name: str = "remote_job") -> list[int]:
        """The node's Ray worker processes running a task ``name`` now (``ray::<name>``)."""
        return [pid for pid, cmd in self.processes().items() if cmd.startswith(f"ray::{name}")]

    def kill(self) -> int:
        """SIGKILL every process of the node at once; returns how many were signalled."""
        pids = list(self.processes())
        _kill(pids)
        return len(pids)

    def stop(self, timeout_s: float = 30.0) -> None:
        """SIGTERM ``ray start --block`` (it stops its node), then SIGKILL what is left."""
        pids = set(self.processes())
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGTERM)
            with contextlib.suppress(subprocess.TimeoutExpired):
                self.proc.wait(timeout_s)
        time.sleep(0.5)
        _kill(sorted((pids | set(self.processes())) - {self.proc.pid}))
        if self.proc.poll() is None:
            self.proc.kill()
        self.proc.wait()


class Cluster:
    """A head and worker nodes on this machine, started as the README says.

    ``work``: a folder for the nodes' temp dirs, homes and logs. ``port``: the head's GCS
    port (a free block of 500 ports from there on is used for the nodes' other ports).
    """

    def __init__(self, work: Path, port: int | None = None) -> None:
        self.work = work
        self.port = port or free_port_block()
        self.ip = "127.0.0.1"
        self.head_home = work / "head_home"
        # Ray's socket paths live under --temp-dir and may not exceed 107 bytes (AF_UNIX):
        # a short folder of its own, removed by stop().
        self.temp_root = Path(tempfile.mkdtemp(prefix="rc", dir="/tmp"))
        self.nodes: dict[str, Node] = {}
        self.started: list[Node] = []
        self.commands = readme_commands()
        self._next_port = self.port + 10

    # -- the README's commands, with this machine's isolation flags ------------------------

    @property
    def address(self) -> str:
        return f"{self.ip}:{self.port}"

    @property
    def token_file(self) -> Path:
        return self.head_home / ".ray" / "auth_token"

    def _readme(self, kind: str) -> str:
        marks = {
            "token": "get-auth-token",
            "head": "ray start --head",
            "worker": "ray start --address",
            "pipeline": "sumo_ayss.pipeline",
        }
        found = [c for c in self.commands if marks[kind] in c]
        if len(found) != 1:
            raise RuntimeError(f"README cluster block: {len(found)} '{marks[kind]}' commands")
        return self.substitute(found[0])

    def substitute(self, command: str) -> str:
        """A README command for this machine: the venv's tools, the head's address and port,
        the token; nothing else changed."""
        command = command.replace(".venv/bin/", f"{BIN}/")
        command = command.replace("HEAD:6379", self.address).replace("--port 6379", "")
        if "<token>" in command:
            command = command.replace("<token>", shlex.quote(self.token_file.read_text()))
        return command

    def generate_token(self) -> str:
        """The README's token command, run with the head's home folder; returns the token."""
        self.head_home.mkdir(parents=True, exist_ok=True)
        env = {**os.environ, "HOME": str(self.head_home)}
        subprocess.run(  # it prints the token: kept out of the drill's output
            ["bash", "-c", self._readme("token")],
            env=env,
            check=True,
            timeout=60,
            capture_output=True,
        )
        return self.token_file.read_text()

    def _ports(self, n: int) -> list[int]:
        ports = list(range(self._next_port, self._next_port + n))
        self._next_port += n
        return ports

    def _isolation(self, name: str, head: bool, cpus: int) -> str:
        agent, worker_lo = self._ports(1)[0], self._ports(200)[0]
        flags = [
            "--block",
            f"--num-cpus {cpus}",
            f"--resources '{{\"{name}\": 1}}'",
            f"--temp-dir {self.temp_root / name}",
            f"--dashboard-agent-listen-port {agent}",
            f"--min-worker-port {worker_lo} --max-worker-port {worker_lo + 199}",
            "--object-store-memory 100000000",
            "--disable-usage-stats",
        ]
        if head:
            flags += [
                f"--port {self.port}",
                f"--node-ip-address {self.ip}",
                "--include-dashboard false",
                f"--dashboard-port {self.port + 1}",
                f"--ray-client-server-port {self.port + 2}",
            ]
        else:
            flags.append(f"--node-ip-address {self.ip}")
        return " ".join(flags)

    def start_head(self, cpus: int = 1) -> Node:
        """The token (the README's command, once) and the head."""
        if not self.token_file.is_file():
            self.generate_token()
        return self._start("head", self._readme("head"), self.head_home, True, cpus, None, None)

    def start_worker(self, name: str, cwd: Path, cpus: int = 1, hide: Path | None = None) -> Node:
        """A worker node with its own home (no token file) and working directory ``cwd``;
        ``hide``: a folder covered by an empty tmpfs in the node's private mount namespace."""
        home = self.work / f"{name}_home"
        return self._start(name, self._readme("worker"), home, False, cpus, cwd, hide)

    def _start(
        self,
        name: str,
        command: str,
        home: Path,
        head: bool,
        cpus: int,
        cwd: Path | None,
        hide: Path | None,
    ) -> Node:
        home.mkdir(parents=True, exist_ok=True)
        (cwd or home).mkdir(parents=True, exist_ok=True)
        temp = self.temp_root / name
        temp.mkdir(parents=True, exist_ok=True)
        log = self.work / f"{name}.log"
        full = f"{command} {self._isolation(name, head, cpus)}"
        argv = ["bash", "-c", f"exec env {full}"]
        if hide is not None:
            mount = f"mount -t tmpfs -o size=1m tmpfs {shlex.quote(str(hide))}"
            argv = [*unshare_argv(), "bash", "-c", f"{mount} && exec env {full}"]
        env = {**os.environ, "HOME": str(home)}
        for key in ("RAY_AUTH_MODE", "RAY_AUTH_TOKEN", "RAY_AUTH_TOKEN_PATH", "RAY_ADDRESS"):
            env.pop(key, None)  # only what the README's command sets
        with open(log, "wb") as out:
            proc = subprocess.Popen(
                argv,
                cwd=cwd or home,
                env=env,
                stdout=out,
                stderr=subprocess.STDOUT,
                start_new_session=True,
            )
        node = Node(name, proc, temp, log)
        self.nodes[name] = node
        self.started.append(node)
        self._wait_up(node)
        return node

    def _wait_up(self, node: Node, timeout_s: float = 120.0) -> None:
        t0 = time.monotonic()
        while time.monotonic() - t0 < timeout_s:
            text = node.log.read_text(errors="replace")
            if "--block" in text and "block forever" in text:
                return
            if node.proc.poll() is not None:
                raise RuntimeError(f"node {node.name} exited: {_tail(node.log)}")
            time.sleep(0.5)
        raise RuntimeError(f"node {node.name} did not start in {timeout_s:.0f} s")

    def _pipeline(self) -> tuple[dict[str, str], list[str]]:
        command = self._readme("pipeline")
        prefix = re.match(r"^((?:[A-Z_]+=\S+\s+)*)", command)
        assert prefix is not None
        assignments = dict(a.split("=", 1) for a in shlex.split(prefix.group(1)))
        return assignments, shlex.split(command[prefix.end() :])

    def driver_env(self) -> dict[str, str]:
        """The pipeline's environment: the README command's variables (``RAY_AUTH_MODE``)
        and the token's file (the README's driver runs on the head, where
        ``~/.ray/auth_token`` holds it; here ``RAY_AUTH_TOKEN_PATH`` names the head's)."""
        env = {k: v for k, v in os.environ.items() if not k.startswith(("RAY_AUTH", "RAY_ADDR"))}
        env.update(self._pipeline()[0])
        env["RAY_AUTH_TOKEN_PATH"] = str(self.token_file)
        return env

    def pipeline_command(self, config: Path, *extra: str) -> list[str]:
        """The README's pipeline command for ``config`` (``configs/paper.yaml`` replaced)."""
        argv = [str(config) if a == "configs/paper.yaml" else a for a in self._pipeline()[1]]
        return [*argv, *extra]

    def stop(self) -> None:
        """Stop every node started here (worker nodes first)."""
        for name in sorted(self.nodes, key=lambda n: n == "head"):
            self.nodes[name].stop()
        self.nodes.clear()
        shutil.rmtree(self.temp_root, ignore_errors=True)

    def leftovers(self) -> list[str]:
        """Processes of nodes started here that are still alive (should be none)."""
        out = []
        for node in self.started:
            out += [f"{pid} {cmd[:60]}" for pid, cmd in node.processes().items()]
        return out


def _tail(path: Path, n: int = 2000) -> str:
    return path.read_text(errors="replace")[-n:]
