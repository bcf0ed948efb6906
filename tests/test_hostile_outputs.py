"""Hostile use of the outputs: no destroyed file, no orphaned process, no lying exit code.

An output onto a device, a FIFO or a link writes through it or follows it,
never replaces it; two outputs onto one file, or an output onto an input, are
refused before any work, as is a path that cannot be written; a full disk
leaves nothing behind; a signal ends the worker processes with the command;
what a method does to its process (ends it, prints, closes stdout, raises
what is not an Exception) costs its run, and the exit code says so.
"""

import contextlib
import json
import os
import signal
import stat
import subprocess
import sys
import textwrap
import threading
import time
from pathlib import Path

import pytest

from signorini.cli import main

ROOT = os.geteuid() == 0
#: the command in a process of its own runs this checkout
ENV = {**os.environ, "PYTHONPATH": str(Path(__file__).resolve().parents[1])}
METHODS = textwrap.dedent("""
    import os
    import sys
    import time

    from signorini.solvers.pdas import pdas


    class Boom(BaseException):
        pass


    def exits(problem, **options):
        os._exit(0)

    def boom(problem, **options):
        raise Boom("bang")

    def closes(problem, **options):
        sys.stdout.close()
        return pdas(problem)

    def prints(problem, **options):
        print("printed by the method")
        os.write(1, b"written to fd 1 by the method\\n")
        return pdas(problem)

    def wanders(problem, **options):
        os.chdir("/")
        return pdas(problem)

    def sleeps(problem, **options):
        time.sleep(300)
""")


@pytest.fixture
def here(tmp_path, monkeypatch):
    """The working folder, with the user's methods in m.py and a scene file s.toml."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "m.py").write_text(METHODS)
    (tmp_path / "s.toml").write_text("[mesh]\n")
    return tmp_path


def listing(folder):
    return sorted((str(p.relative_to(folder)), stat.S_IFMT(p.lstat().st_mode))
                  for p in folder.rglob("*"))


def one_line(err, *words, progress=False):
    """The error is one line naming ``words`` (after the progress lines a study prints)."""
    lines = err.strip().splitlines()
    assert "Traceback" not in err and (progress or len(lines) == 1), err
    assert lines[-1].startswith("signorini: "), err
    for word in words:
        assert word in lines[-1], (word, lines[-1])


#: refused before any work, exit 2, one line naming the flags; nothing written
REFUSED = [
    (["solve", "block", "--json", "out.vtu", "--vtk", "out.vtu"], ["--json", "--vtk", "same file"]),
    (["solve", "block", "--json", "alias.vtu", "--vtk", "b.vtu"], ["--json", "--vtk", "same file"]),
    (["crosscheck", "block", "--json", "x", "--md", "x"], ["--json", "--md", "same file"]),
    (["crosscheck", "block", "--json", "-", "--md", "/dev/stdout"], ["--json", "--md"]),
    (["solve", "s.toml", "--json", "s.toml"], ["--json", "scene file", "input"]),
    (["solve", "block", "--method", "m.py:exits", "--json", "m.py"], ["--json", "m.py", "input"]),
    (["crosscheck", "block", "--method", "pdas", "--method", "m.py:exits", "--md", "m.py"],
     ["--md", "m.py", "input"]),
    (["solve", "block", "--json", "r.json", "--vtk", "/proc/self/r.vtu"], ["--vtk", "/proc/self"]),
    (["solve", "block", "--json", "r.json", "--vtk", "/sys/r.vtu"], ["--vtk", "/sys"]),
    (["solve", "block", "--json", "r.json", "--vtk", "folder.vtu"], ["--vtk", "is a directory"]),
    (["solve", "block", "--json", "r.json", "--vtk", ""], ["--vtk", "empty"]),
    (["solve", "block", "--json", ""], ["--json", "empty"]),
    (["crosscheck", "block", "--md", ""], ["--md", "empty"]),
    (["validate", "--out", ""], ["--out", "empty"]),
    (["sweep", "block", "--load", "0.01:0.02:2", "--out", ""], ["--out", "empty"]),
    (["validate", "--out", "m.py"], ["--out", "is a file"]),
    (["converge", "hertz-cylinder", "--out", "m.py/report"], ["--out", "is a file"]),
    (["solve", "fifo.toml"], ["fifo.toml", "not a regular file"]),
    (["solve", "block", "--method", "fifo.py:solve"], ["fifo.py", "not a regular file"]),
    (["bench", "--report-only", "--out", "folder.vtu"], ["--report-only", "bench.csv"]),
]


@pytest.mark.parametrize("argv, words", REFUSED, ids=[" ".join(a)[:60] for a, _ in REFUSED])
def test_a_hostile_output_is_refused_before_any_work(capsys, here, argv, words):
    (here / "folder.vtu").mkdir()
    (here / "alias.vtu").symlink_to("b.vtu")
    os.mkfifo(here / "fifo.toml")
    os.mkfifo(here / "fifo.py")
    before = listing(here)
    code = main(argv)
    out, err = capsys.readouterr()
    assert code == 2, (code, err)
    one_line(err, *words)
    assert listing(here) == before
    assert out == ""


def test_a_bench_method_that_is_not_installed_is_refused_naming_the_extra(capsys, here):
    from signorini.solvers.registry import get_method

    if get_method("qp-mosek").installed:
        pytest.skip("mosek is installed here: 'qp-mosek' would run")
    assert main(["bench", "--method", "qp-mosek", "--out", "b"]) == 2
    one_line(capsys.readouterr().err, "qp-mosek", "pip install")
    assert not (here / "b").exists()


@pytest.mark.skipif(not ROOT, reason="chattr +i (an immutable folder) needs root")
def test_an_immutable_folder_or_file_is_refused_before_any_work(capsys, here):
    (here / "locked").mkdir()
    (here / "kept.json").write_text("kept\n")
    if subprocess.run(["chattr", "+i", "locked", "kept.json"], capture_output=True).returncode:
        pytest.skip("this file system takes no immutable flag (chattr +i failed)")
    try:
        assert main(["solve", "block", "--json", "r.json", "--vtk", "locked/r.vtu"]) == 2
        one_line(capsys.readouterr().err, "--vtk", "locked")
        assert main(["solve", "block", "--json", "kept.json"]) == 2
        one_line(capsys.readouterr().err, "--json", "kept.json")
        assert not (here / "r.json").exists() and (here / "kept.json").read_text() == "kept\n"
    finally:
        subprocess.run(["chattr", "-i", "locked", "kept.json"])


def test_a_link_is_followed_and_kept(capsys, here):
    (here / "target.json").write_text("old\n")
    (here / "link.json").symlink_to("target.json")
    (here / "dangling.json").symlink_to("new.json")
    assert main(["solve", "block", "--json", "link.json"]) == 0
    assert main(["solve", "block", "--json", "dangling.json"]) == 0
    for link, target in (("link.json", "target.json"), ("dangling.json", "new.json")):
        assert (here / link).is_symlink() and os.readlink(here / link) == target
        assert json.loads((here / target).read_text())["status"] == "converged"


def test_a_fifo_is_written_through_not_replaced(capsys, here):
    os.mkfifo(here / "pipe")
    got = []
    reader = threading.Thread(target=lambda: got.append((here / "pipe").read_text()))
    reader.start()
    assert main(["solve", "block", "--json", "pipe"]) == 0
    reader.join(timeout=60)
    assert stat.S_ISFIFO((here / "pipe").lstat().st_mode)
    assert json.loads(got[0])["status"] == "converged"


@pytest.mark.skipif(not ROOT, reason="making a device (mknod) needs root")
def test_a_device_is_written_through_not_replaced(capsys, here):
    os.mknod(here / "null", stat.S_IFCHR | 0o666, os.makedev(1, 3))  # a /dev/null of our own
    os.symlink("null", here / "null.vtu")
    assert main(["solve", "block", "--json", "null", "--vtk", "null.vtu"]) == 0
    assert stat.S_ISCHR((here / "null").lstat().st_mode) and (here / "null.vtu").is_symlink()
    assert main(["crosscheck", "block", "--method", "pdas", "--method", "uzawa",
                 "--json", "null", "--md", "null"]) == 0  # one device may take several outputs
    assert stat.S_ISCHR((here / "null").lstat().st_mode)


def test_this_process_stdout_by_its_name_is_stdout(capsys, here):
    assert main(["solve", "block", "--json", "/proc/self/fd/1"]) == 0
    assert json.loads(capsys.readouterr().out)["status"] == "converged"
    assert not (here / "1").exists()


def test_a_method_that_changes_folder_moves_no_output(capsys, here):
    assert main(["solve", "block", "--method", "m.py:wanders", "--json", "r.json"]) == 0
    assert json.loads((here / "r.json").read_text())["status"] == "converged"


def test_a_method_that_ends_its_process_ends_failed_not_zero(capsys, here):
    code = main(["solve", "block", "--method", "m.py:exits", "--json", "r.json"])
    assert code == 1
    record = json.loads((here / "r.json").read_text())
    assert record["status"] == "failed" and "worker process died" in record["message"]


@pytest.mark.parametrize("function", ["boom", "closes", "prints"])
def test_what_a_method_does_to_stdout_cannot_corrupt_the_json(capsys, here, function):
    code = main(["solve", "block", "--method", f"m.py:{function}", "--json", "-"])
    out, err = capsys.readouterr()
    record = json.loads(out)  # nothing but the record on stdout
    assert "Traceback" not in err
    assert (code, record["status"]) == ((1, "failed") if function == "boom" else (0, "converged"))


def cli(*argv):
    """The command in a process of its own, in the working folder."""
    return subprocess.run([sys.executable, "-m", "signorini.cli", *argv], capture_output=True,
                          text=True, env=ENV, timeout=300)


def test_a_user_method_that_prints_leaves_stdout_to_the_json(here):
    for argv in (["solve", "block", "--method", "m.py:prints"],
                 ["crosscheck", "block", "--method", "pdas", "--method", "m.py:prints"]):
        done = cli(*argv, "--json", "-")
        assert done.returncode == 0, done.stderr
        json.loads(done.stdout)


@pytest.mark.parametrize("argv", [["solve", "block"], ["methods"]])
def test_a_closed_stdout_is_refused(here, argv):
    done = subprocess.run(["sh", "-c", 'exec "$@" >&-', "sh", sys.executable, "-m",
                           "signorini.cli", *argv], capture_output=True, text=True, timeout=300,
                          env=ENV)
    assert done.returncode == 2
    one_line(done.stderr, "standard output is closed")


def test_a_pipe_closed_by_its_reader_fails_in_one_line(here):
    read, write = os.pipe()
    os.close(read)  # the reader is gone before anything is written
    try:
        done = subprocess.run([sys.executable, "-m", "signorini.cli", "solve", "block", "--json", "-"],
                              stdout=write, stderr=subprocess.PIPE, text=True, timeout=300,
                              env={**ENV, "PYTHONUNBUFFERED": "1"})
    finally:
        os.close(write)
    assert done.returncode == 1
    one_line(done.stderr, "standard output was closed")


@pytest.fixture
def full_disk(tmp_path):
    """A tiny file system with no room left."""
    if not ROOT:
        pytest.skip("mounting a full tmpfs needs root")
    folder = tmp_path / "full"
    folder.mkdir()
    if subprocess.run(["mount", "-t", "tmpfs", "-o", "size=64k", "tmpfs", str(folder)],
                      capture_output=True).returncode:
        pytest.skip("mount -t tmpfs failed here (no privilege to mount in this container)")
    try:
        with open(folder / "filler", "wb", buffering=0) as handle:
            with contextlib.suppress(OSError):  # until the disk is full
                while True:
                    handle.write(b"\0" * 1024)
        yield folder
    finally:
        subprocess.run(["umount", str(folder)])


@pytest.mark.parametrize("argv", [
    ["solve", "block", "--json", "{full}/r.json"],
    ["solve", "block", "--json", "r.json", "--vtk", "{full}/r.vtu"],
    ["crosscheck", "block", "--method", "pdas", "--method", "uzawa", "--md", "{full}/x.md"],
    ["validate", "--case", "block", "--method", "pdas", "--out", "{full}/v"],
])
def test_a_full_disk_is_one_line_and_leaves_nothing(capsys, here, full_disk, argv):
    before = listing(full_disk)
    code = main([a.replace("{full}", str(full_disk)) for a in argv])
    assert code == 1
    one_line(capsys.readouterr().err, "No space left", str(full_disk), progress=True)
    assert listing(full_disk) == before
    assert not (here / "r.json").exists()  # every output of the command, or none


def children_of(pid):
    psutil = pytest.importorskip("psutil", reason="psutil finds the worker processes")
    return psutil.Process(pid).children(recursive=True)


@pytest.mark.slow
@pytest.mark.parametrize("argv, signum, group", [
    (["solve", "block", "--method", "m.py:sleeps", "--time-limit", "60"], signal.SIGTERM, False),
    (["solve", "block", "--method", "m.py:sleeps", "--time-limit", "60"], signal.SIGINT, True),
    (["solve", "block", "--method", "m.py:sleeps"], signal.SIGINT, False),
    (["validate", "--method", "m.py:sleeps", "--case", "block", "--out", "v"], signal.SIGTERM, False),
    (["validate", "--method", "m.py:sleeps", "--case", "block", "--out", "v"], signal.SIGINT, True),
])
def test_a_signal_ends_the_workers_with_the_command(here, argv, signum, group):
    # as from a terminal: SIGINT at its default (a shell running the tests in the background
    # ignores it, and Python then keeps it ignored instead of raising KeyboardInterrupt)
    command = subprocess.Popen([sys.executable, "-m", "signorini.cli", *argv], env=ENV,
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                               start_new_session=True,
                               preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    deadline = time.monotonic() + 120  # generous: the worker starts with the package's imports
    while not children_of(command.pid) and time.monotonic() < deadline:
        time.sleep(0.1)
    workers = children_of(command.pid)
    assert workers, "no worker process was started"
    (os.killpg if group else os.kill)(command.pid, signum)
    _, err = command.communicate(timeout=120)
    assert command.returncode == 128 + signum
    one_line(err, "stopped by", signal.Signals(signum).name, progress=True)
    import psutil

    _, alive = psutil.wait_procs(workers, timeout=30)  # generous: they were killed before the exit
    assert alive == []
    assert not (here / "v").exists()  # a folder that nothing was written into is not left


def test_every_output_is_made_absolute_before_any_work(here):
    from signorini.files import check_outputs

    got = check_outputs({"--json": "r.json", "--md": "-"}, {"--out": "report/deeper"})
    assert got == {"--json": str(here / "r.json"), "--md": "-", "--out": str(here / "report/deeper")}
    assert listing(here) == [("m.py", stat.S_IFREG), ("s.toml", stat.S_IFREG)]  # nothing made


def test_a_replaced_file_keeps_its_permissions(capsys, here):
    (here / "r.json").write_text("old\n")
    (here / "r.json").chmod(0o640)
    assert main(["solve", "block", "--json", "r.json"]) == 0
    assert stat.S_IMODE((here / "r.json").stat().st_mode) == 0o640
    assert json.loads((here / "r.json").read_text())["status"] == "converged"
