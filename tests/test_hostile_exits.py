"""Every exit path leaves the outputs whole or absent: two outputs on one file are refused
across a command's options (a file inside an output folder that folder writes, too), a
write that never finished leaves no partial file, and a full disk or a full stdout ends in
one line and exit 1.
"""

import errno
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from signorini import files
from signorini.cli import main
from signorini.errors import OutputError

ENV = {**os.environ, "PYTHONPATH": str(Path(__file__).resolve().parents[1])}


def one_line(capsys, argv, code):
    assert main(argv) == code
    err = capsys.readouterr().err.strip().splitlines()
    assert err and "Traceback" not in "\n".join(err), err
    return err[-1]


# --- two outputs on one file ------------------------------------------------------------------

@pytest.mark.parametrize("junit", ["report.json", "report.md", "case-pressure.png"])
def test_a_file_output_that_the_report_folder_writes_is_refused(tmp_path, capsys, junit):
    out = tmp_path / "v"
    out.mkdir()
    err = one_line(capsys, ["validate", "--out", str(out), "--junit", str(out / junit)], 2)
    assert "--junit" in err and "--out" in err and "writes" in err, err
    assert list(out.iterdir()) == []


def test_an_input_that_the_report_folder_would_write_over_is_refused(tmp_path, capsys):
    out = tmp_path / "v"
    out.mkdir()
    with open(out / "report.json", "wb") as handle:  # a problem file under a report's name
        np.savez(handle, K=np.eye(1), f=np.ones(1), N=np.ones((1, 1)), d=np.ones(1))
    before = (out / "report.json").read_bytes()
    err = one_line(capsys, ["validate", "--out", str(out), "--problem", str(out / "report.json")], 2)
    assert "--out" in err and "would write over the problem file" in err, err
    assert (out / "report.json").read_bytes() == before


def test_a_junit_file_beside_the_report_is_taken(tmp_path):
    (tmp_path / "v").mkdir()
    checked = files.check_outputs({"--junit": str(tmp_path / "v" / "junit.xml")},
                                  {"--out": str(tmp_path / "v")},
                                  fills={"--out": ("report.md", "report.json", "*.png")})
    assert checked["--junit"] == str(tmp_path / "v" / "junit.xml")


def test_two_staged_outputs_on_one_file_write_neither(tmp_path):
    target = tmp_path / "report.json"
    target.write_text("before")
    with pytest.raises(OutputError, match="same file"):
        with files.all_or_none():
            files.atomic_write_text(target, "first")
            files.atomic_write_text(tmp_path / "." / "report.json", "second")
    assert target.read_text() == "before"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["report.json"]


# --- partial files ----------------------------------------------------------------------------

def test_a_write_that_never_finished_is_swept_at_exit(tmp_path):
    """A worker killed while writing (SIGKILL runs no clean-up) leaves its temporary file in a
    folder of the command's output: the command removes it as it ends."""
    from signorini.cli.app import _clean_up

    out = files.writable_directory(tmp_path / "bench")
    (out / "problems").mkdir()
    left = out / "problems" / f".x-file.reference.npz{files.PARTIAL}abc123.npz"
    left.write_bytes(b"half")
    kept = out / "problems" / "x-file.npz"
    kept.write_bytes(b"whole")
    _clean_up()
    assert not left.exists() and kept.read_bytes() == b"whole"


def test_an_interrupt_while_bench_copies_a_problem_leaves_no_copy(tmp_path, capsys, monkeypatch):
    from signorini.problem.contact import ContactProblem

    problem = tmp_path / "mine.npz"
    np.savez(problem, K=np.diag([2.0, 1.0]), f=np.ones(2), N=np.array([[1.0, 0.0]]),
             d=np.array([0.25]))
    real = ContactProblem.save

    def interrupted(self, path):  # the copy is half written when SIGINT arrives
        def half(name):
            Path(name).write_bytes(b"PK\x03\x04 half")
            raise KeyboardInterrupt

        files.atomic_write(path, half)

    monkeypatch.setattr(ContactProblem, "save", interrupted)
    out = tmp_path / "b"
    assert main(["bench", "--problem", str(problem), "--method", "pdas", "--out", str(out)]) == 130
    left = [p for p in out.rglob("*") if p.is_file()] if out.exists() else []
    assert left == [], left
    monkeypatch.setattr(ContactProblem, "save", real)


def test_a_bench_whose_scene_cannot_be_meshed_leaves_nothing(tmp_path, capsys):
    out = tmp_path / "b"
    # the relaxed mesher gives up on so slow a grading (Triangle meshes it)
    err = one_line(capsys, ["bench", "--set", "grading=1e-4", "--set", "n_contact=10", "--set",
                            "mesher=relaxed", "--sizes", "0",
                            "--method", "pdas", "--out", str(out)], 2)
    assert "could not be meshed" in err and "grading" in err, err
    assert not out.exists(), list(out.rglob("*"))


# --- a full disk, a full stdout ---------------------------------------------------------------

def test_a_full_disk_during_validate_is_one_line_and_leaves_nothing(tmp_path, capsys, monkeypatch):
    real = Path.write_bytes

    def full(self, data):
        if files.PARTIAL in self.name:  # every result file is produced under its temporary name
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        return real(self, data)

    monkeypatch.setattr(Path, "write_bytes", full)
    out = tmp_path / "v"
    argv = ["validate", "--case", "block", "--method", "pdas", "--out", str(out),
            "--junit", str(tmp_path / "j.xml")]
    assert main(argv) == 1
    err = capsys.readouterr().err.strip().splitlines()
    mine = [line for line in err if line.startswith("signorini:")]
    assert len(mine) == 1 and "No space left on device" in mine[0] and "Traceback" not in err, err
    assert not out.exists() and not (tmp_path / "j.xml").exists()


@pytest.mark.skipif(not os.path.exists("/dev/full"), reason="no /dev/full on this system")
@pytest.mark.parametrize("argv", [["solve", "block", "--set", "nx=4", "--set", "ny=4"],
                                  ["solve", "block", "--set", "nx=4", "--set", "ny=4", "--json", "-"],
                                  ["methods"]])
def test_a_full_stdout_is_one_line_and_exit_1(argv):
    with open("/dev/full", "w") as full:
        done = subprocess.run([sys.executable, "-m", "signorini.cli", *argv], stdout=full,
                              stderr=subprocess.PIPE, text=True, env=ENV, timeout=300)
    lines = done.stderr.strip().splitlines()
    assert done.returncode == 1, done.stderr
    assert len(lines) == 1 and "standard output" in lines[0] and "No space" in lines[0], lines
