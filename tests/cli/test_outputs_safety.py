"""Files are never lost: every output is written to a temporary file next to it and renamed
into place whole; an output that names one of the command's inputs (also through a link) is
refused before anything is solved; Ctrl-C once the rows are solved still writes them all."""

from __future__ import annotations

import errno
import os
import shutil
import signal
from pathlib import Path

import numpy as np
import pytest

from symkin import cli, outfiles
from symkin.runtime.outputs.results import Trajectory

ROOT = Path(__file__).resolve().parents[2]
CRANK_SLIDER = ROOT / "examples" / "crank_slider.yaml"
LOADED = ROOT / "examples" / "crank_slider_load.yaml"
OLD = b"the user's file, which must survive\n"


def _copy(tmp_path: Path, source: Path = CRANK_SLIDER) -> Path:
    mechanism = tmp_path / source.name
    shutil.copyfile(source, mechanism)
    return mechanism


@pytest.mark.parametrize("flag, name", [("-o", "out.csv"), ("-o", "out.npz"),
                                        ("--plot", "out.png"), ("--html", "out.html"),
                                        ("--animate", "out.gif")])
def test_an_output_linked_to_the_mechanism_file_is_refused(tmp_path, capsys, flag, name):
    mechanism = _copy(tmp_path)
    before = mechanism.read_bytes()
    (tmp_path / name).symlink_to(mechanism)
    status = cli.main(["run", str(mechanism), "--backend", "numpy", flag,
                       str(tmp_path / name)])
    err = capsys.readouterr().err
    assert status == 2, err
    assert "is the mechanism file" in err and flag in err, err
    assert mechanism.read_bytes() == before


def test_the_forces_figure_next_to_plot_may_not_be_the_mechanism_file(tmp_path, capsys):
    mechanism = _copy(tmp_path, LOADED)
    before = mechanism.read_bytes()
    (tmp_path / "run_forces.png").symlink_to(mechanism)
    status = cli.main(["run", str(mechanism), "--backend", "numpy", "--plot",
                       str(tmp_path / "run.png")])
    assert status == 2 and "run_forces.png" in capsys.readouterr().err
    assert mechanism.read_bytes() == before and not (tmp_path / "run.png").exists()


def test_a_hard_link_to_the_mechanism_file_is_refused(tmp_path, capsys):
    mechanism = _copy(tmp_path)
    (tmp_path / "sub").mkdir()
    os.link(mechanism, tmp_path / "sub" / "hard.csv")
    output = tmp_path / "sub" / ".." / "sub" / "hard.csv"
    status = cli.main(["run", str(mechanism), "--backend", "numpy", "-o", str(output)])
    assert status == 2 and "is the mechanism file" in capsys.readouterr().err
    assert mechanism.read_bytes() == CRANK_SLIDER.read_bytes()


@pytest.mark.parametrize("flag, name", [("-o", "out.npz"), ("--plot", "out.png")])
def test_a_sweep_output_linked_to_its_inputs_is_refused(tmp_path, capsys, flag, name):
    mechanism = _copy(tmp_path)
    table = tmp_path / "sets.csv"
    table.write_text("b\n5\n5.5\n")
    for read in (mechanism, table):
        link = tmp_path / name
        link.unlink(missing_ok=True)
        link.symlink_to(read)
        before = read.read_bytes()
        status = cli.main(["sweep", str(mechanism), "--backend", "numpy", "--params",
                           str(table), flag, str(link)])
        assert status == 2 and "the command reads it" in capsys.readouterr().err
        assert read.read_bytes() == before


def _full_disk_savetxt(real):
    """np.savetxt that writes part of the table, then meets a full disk (ENOSPC)."""

    def savetxt(path, table, **options):
        real(path, table[: len(table) // 2], **options)
        raise OSError(errno.ENOSPC, "No space left on device", str(path))

    return savetxt


def test_a_full_disk_leaves_the_old_results_whole(tmp_path, capsys, monkeypatch):
    out = tmp_path / "out.csv"
    out.write_bytes(OLD)
    monkeypatch.setattr(np, "savetxt", _full_disk_savetxt(np.savetxt))
    status = cli.main(["run", str(CRANK_SLIDER), "--backend", "numpy", "-o", str(out)])
    err = capsys.readouterr().err
    assert status == 2 and "No space left on device" in err and str(out) in err, err
    assert out.read_bytes() == OLD
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.csv"]  # no fragment left


def test_a_full_disk_mid_npz_leaves_the_old_file_whole(tmp_path, monkeypatch):
    out = tmp_path / "out.npz"
    out.write_bytes(OLD)
    real = np.savez

    def savez(path, **arrays):  # the first two arrays written, then the disk is full
        real(path, **dict(list(arrays.items())[:2]))
        raise OSError(errno.ENOSPC, "No space left on device", str(path))

    monkeypatch.setattr(np, "savez", savez)
    trajectory = Trajectory(np.zeros(2), np.zeros((2, 1)), np.zeros((2, 1)), np.zeros((2, 1)),
                            ("a.x",))
    with pytest.raises(OSError, match="No space") as raised:
        trajectory.save(out)
    assert raised.value.filename == str(out)  # the user's file named, not the temporary one
    assert out.read_bytes() == OLD and len(list(tmp_path.iterdir())) == 1


def test_the_replaced_file_keeps_its_permissions(tmp_path):
    out = tmp_path / "out.txt"
    out.write_bytes(OLD)
    out.chmod(0o640)
    with outfiles.replacing(out) as temporary:
        temporary.write_text("new")
    assert out.read_text() == "new" and out.stat().st_mode & 0o777 == 0o640


def _interrupting(real):
    """A CSV writer that gets Ctrl-C (a real SIGINT to this process) half-way through."""

    def savetxt(path, table, **options):
        os.kill(os.getpid(), signal.SIGINT)
        real(path, table, **options)

    return savetxt


def test_ctrl_c_while_writing_still_writes_every_row_then_exits_130(tmp_path, capsys,
                                                                     monkeypatch):
    out = tmp_path / "out.csv"
    out.write_bytes(OLD)
    monkeypatch.setattr(np, "savetxt", _interrupting(np.savetxt))
    status = cli.main(["run", str(CRANK_SLIDER), "--backend", "numpy", "--dt", "0.001", "-o",
                       str(out)])
    err = capsys.readouterr().err
    assert status == 130, err
    assert "interrupted after the solve" in err and "1501 time points" in err, err
    table = np.loadtxt(out, delimiter=",", skiprows=1)
    assert table.shape[0] == 1501 and table[-1, 0] == pytest.approx(1.5)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.csv"]


def test_ctrl_c_while_the_api_writes_leaves_the_old_file(tmp_path, monkeypatch):
    out = tmp_path / "out.csv"
    out.write_bytes(OLD)

    def savetxt(path, table, **options):  # half a file, then Ctrl-C
        np.savetxt.__wrapped__(path, table[:1], **options)  # type: ignore[attr-defined]
        raise KeyboardInterrupt

    savetxt.__wrapped__ = np.savetxt  # type: ignore[attr-defined]
    monkeypatch.setattr(np, "savetxt", savetxt)
    trajectory = Trajectory(np.zeros(3), np.zeros((3, 1)), np.zeros((3, 1)), np.zeros((3, 1)),
                            ("a.x",))
    with pytest.raises(KeyboardInterrupt):
        trajectory.save(out)
    assert out.read_bytes() == OLD and len(list(tmp_path.iterdir())) == 1
