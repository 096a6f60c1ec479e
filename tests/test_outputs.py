"""Output files: write failures are bad input (exit 2, no partial file), extensions, --force."""

from __future__ import annotations

import errno
import importlib
import importlib.util
import json
import os
import shutil
import socket
import subprocess
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from cartpole_q.envs.gym import display_problem
from cartpole_q.errors import UserError, WriteError
from cartpole_q.store import atomic
from cartpole_q.store.atomic import atomic_write_bytes
from tests.conftest import invoke

UNWRITABLE = [
    ("/proc/x.png", "files cannot be created in /proc"),
    ("/etc/passwd/x.png", "/etc/passwd is not a directory"),
    ("/sys/x.png", "/sys"),  # read-only (sysfs), even for root
]


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("outputs") / "run"
    assert invoke("train", "--out", out, "-q").exit_code == 0
    return out


def _mount_tmpfs(path: Path, options: str) -> Iterator[Path]:
    path.mkdir()
    mounted = subprocess.run(
        ["mount", "-t", "tmpfs", "-o", options, "tmpfs", str(path)],
        capture_output=True,
        check=False,
    )
    if mounted.returncode != 0:
        pytest.skip(f"cannot mount a tmpfs here: {mounted.stderr.decode().strip()}")
    try:
        yield path
    finally:
        subprocess.run(["umount", str(path)], check=False)


@pytest.fixture
def full_disk(tmp_path: Path) -> Iterator[Path]:
    """A real 32 KiB file system (tmpfs; needs root, else skipped): big files hit ENOSPC."""
    if shutil.which("mount") is None or os.geteuid() != 0:
        pytest.skip("mounting a tmpfs needs root")
    yield from _mount_tmpfs(tmp_path / "small", "size=32k")


@pytest.fixture
def read_only_disk(tmp_path: Path) -> Iterator[Path]:
    """A read-only tmpfs: even root gets EROFS."""
    if shutil.which("mount") is None or os.geteuid() != 0:
        pytest.skip("mounting a tmpfs needs root")
    yield from _mount_tmpfs(tmp_path / "ro", "ro,size=64k")


def _refused(result: Any, *needles: str) -> None:
    assert result.exit_code == 2, result.output
    assert "Traceback" not in result.output
    message = result.stderr
    assert message.startswith("error: ") and message.count("\n") == 1, message
    for needle in needles:
        assert needle in message, message


def _no_temporaries(directory: Path) -> None:
    assert not list(directory.glob(".*.tmp")), list(directory.iterdir())


@pytest.fixture
def no_play(monkeypatch: pytest.MonkeyPatch) -> None:
    """Fail the test if an episode is played: outputs must be checked before."""

    def played(*args: object, **kwargs: object) -> None:
        raise AssertionError("episodes were played before the output was checked")

    # evaluate_runs binds the name when first imported: imported now, patched in both places,
    # so that no later test finds the patch bound there (the file failed when run alone).
    import cartpole_q.experiments.evaluate_runs

    monkeypatch.setattr("cartpole_q.evaluation.evaluate", played)
    monkeypatch.setattr(cartpole_q.experiments.evaluate_runs, "evaluate", played)


# -- atomic writes ----------------------------------------------------------------------


@pytest.mark.parametrize(("path", "reason"), UNWRITABLE)
def test_atomic_write_failure_is_a_user_error_naming_the_file(path: str, reason: str) -> None:
    with pytest.raises(UserError) as caught:
        atomic_write_bytes(Path(path), b"data")
    assert str(caught.value).startswith(f"{path}: cannot be written: ")
    assert reason in str(caught.value)


def test_a_failed_write_leaves_no_partial_file(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # For machines where no small file system can be mounted: the disk fills up mid-write.
    real_open = open

    class FillsUp:
        def __init__(self, path: Path, mode: str) -> None:
            self._stream = real_open(path, mode)

        def __enter__(self) -> FillsUp:
            return self

        def __exit__(self, *exc_info: object) -> None:
            self._stream.close()

        def write(self, data: bytes) -> int:
            self._stream.write(data[: len(data) // 2])
            self._stream.flush()
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    target = tmp_path / "curve.png"
    target.write_bytes(b"old")
    monkeypatch.setattr(atomic, "open", FillsUp, raising=False)
    with pytest.raises(WriteError, match="no space is left on the device"):
        atomic_write_bytes(target, b"new content")
    assert target.read_bytes() == b"old"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["curve.png"]


def test_a_directory_that_cannot_be_made_is_a_write_error_naming_it(tmp_path: Path) -> None:
    in_the_way = tmp_path / "file"
    in_the_way.write_text("x")
    with pytest.raises(WriteError, match=f"^{in_the_way}: cannot be created: a file is in the way"):
        atomic.make_directory(in_the_way)
    with pytest.raises(WriteError, match=f"{in_the_way} is not a directory"):
        atomic.make_directory(in_the_way / "videos")
    with pytest.raises(WriteError, match="/proc/x: cannot be created: "):
        atomic.make_directory(Path("/proc/x"))


# -- unwritable and full places ---------------------------------------------------------


@pytest.mark.parametrize(("path", "reason"), UNWRITABLE)
def test_plot_into_an_unwritable_place_is_refused(run_dir: Path, path: str, reason: str) -> None:
    _refused(invoke("plot", run_dir, "--out", path), path, reason)
    _refused(invoke("plot", run_dir, "--policy", "--out", path), path, reason)


@pytest.mark.parametrize(("path", "reason"), UNWRITABLE)
def test_video_into_an_unwritable_place_is_refused_before_playing(
    run_dir: Path, path: str, reason: str, no_play: None
) -> None:
    gif = str(Path(path).with_suffix(".gif"))
    _refused(invoke("eval", run_dir, "--video", gif), gif, reason)


def test_read_only_file_system(run_dir: Path, read_only_disk: Path, no_play: None) -> None:
    _refused(invoke("plot", run_dir, "--out", read_only_disk / "p.png"), "read-only")
    _refused(invoke("eval", run_dir, "--video", read_only_disk / "v.gif"), "read-only")
    _refused(invoke("train", "--out", read_only_disk / "run", "-q"), str(read_only_disk))


def test_full_disk_plot_video_and_train(run_dir: Path, full_disk: Path) -> None:
    # each of these files is larger than the 32 KiB file system
    for args in (
        ("plot", run_dir, "--out", full_disk / "p.png"),
        ("plot", run_dir, "--policy", "--out", full_disk / "p.svg"),
        ("eval", run_dir, "--episodes", "1", "--video", full_disk / "v.gif"),
    ):
        _refused(invoke(*args), str(full_disk), "no space is left on the device")
        assert list(full_disk.iterdir()) == []
    run = full_disk / "run"
    _refused(invoke("train", "--out", run, "-q"), str(run), "no space is left on the device")
    _no_temporaries(run)
    assert not (run / "summary.json").exists()


@pytest.fixture
def small_disk(tmp_path: Path) -> Iterator[Path]:
    """A real 256 KiB file system (tmpfs; needs root, else skipped), to fill up by hand."""
    if shutil.which("mount") is None or os.geteuid() != 0:
        pytest.skip("mounting a tmpfs needs root")
    yield from _mount_tmpfs(tmp_path / "small", "size=256k")


def _fill(disk: Path, free_blocks: int) -> Path:
    """Fill ``disk`` up to its last ``free_blocks`` blocks (a tmpfs block is a 4 KiB page)."""
    stats = os.statvfs(disk)
    filler = disk / "filler"
    filler.write_bytes(b"\0" * (stats.f_bavail - free_blocks) * stats.f_frsize)
    assert os.statvfs(disk).f_bavail == free_blocks
    return filler


@pytest.mark.parametrize(
    ("free", "file"),
    [(0, ".lock"), (1, "config.yaml")],
    ids=["no block: the lock file", "one block: the lock file, not config.yaml"],
)
def test_train_into_a_nearly_full_disk_leaves_nothing_half_started(
    small_disk: Path, free: int, file: str
) -> None:
    """The lock file (written first) or config.yaml cannot be written: the directory goes."""
    filler = _fill(small_disk, free)
    run = small_disk / "run"
    result = invoke("train", "--episodes", 30, "--out", run, "-q")
    _refused(result, f"{run / file}: cannot be written", "no space is left on the device")
    assert "The new run directory was removed." in result.stderr
    assert sorted(p.name for p in small_disk.iterdir()) == ["filler"]
    filler.unlink()
    assert invoke("train", "--episodes", 30, "--out", run, "-q").exit_code == 0


def test_a_disk_full_during_training_keeps_a_run_that_resumes(
    small_disk: Path, tmp_path: Path
) -> None:
    """Room for the lock file and config.yaml, not for the first checkpoint."""
    filler = _fill(small_disk, 2)
    run = small_disk / "run"
    args = ("train", "--episodes", 30, "--set", "train.checkpoint_every=10", "-q")
    result = invoke(*args, "--out", run)
    _refused(result, f"{run}/", "no space is left on the device")
    assert (
        f"make room (or fix what refused the write), then resume with `cartpole-q train --resume {run}`"
        in result.stderr
    )
    assert sorted(p.name for p in run.iterdir()) == [".lock", "config.yaml"]
    filler.unlink()
    resumed = invoke("train", "--resume", run, "-q")
    assert resumed.exit_code == 0, resumed.output
    reference = tmp_path / "reference"
    assert invoke(*args, "--out", reference).exit_code == 0
    assert (run / "q_table.npy").read_bytes() == (reference / "q_table.npy").read_bytes()


def test_a_sweep_that_cannot_write_its_points_leaves_nothing(small_disk: Path) -> None:
    """Room for the lock file and one point's config.yaml, not the second's."""
    sweep = small_disk.parent / "s.yaml"
    sweep.write_text("seeds: 0\ngrid:\n  agent.alpha: [0.1, 0.2, 0.3]\n")
    filler = _fill(small_disk, 2)
    out = small_disk / "sweep"
    result = invoke("sweep", sweep, "--out", out, "-q")
    _refused(result, f"{out}/points/", "no space is left on the device", "was removed")
    assert sorted(p.name for p in small_disk.iterdir()) == ["filler"]
    filler.unlink()


# -- directory names that are not UTF-8 -------------------------------------------------


def test_a_directory_name_that_is_not_utf8_works_end_to_end(tmp_path: Path) -> None:
    """``--out $'bad\\xffname'``: the name reaches Python with a surrogate escape."""
    run = tmp_path / os.fsdecode(b"bad\xffname")
    result = invoke("train", "--episodes", 30, "--out", run)
    assert result.exit_code == 0, result.output
    assert result.stdout_bytes.splitlines()[-1] == os.fsencode(run)  # the name's own bytes
    for name in ("summary.json", "reward_curve.png", "q_table.npy"):
        assert (run / name).is_file(), name
    resumed = invoke("train", "--resume", run, "--episodes", 40, "-q")
    assert resumed.exit_code == 0, resumed.output
    assert json.loads((run / "summary.json").read_text())["episodes"] == 40
    assert invoke("plot", run, run, "--out", tmp_path / "two.png").exit_code == 0


def test_a_tune_directory_name_that_is_not_utf8_gets_its_best_yaml(tmp_path: Path) -> None:
    pytest.importorskip("optuna")
    tune = tmp_path / "t.yaml"
    tune.write_text(
        "base: {train: {episodes: 20}, eval: {episodes: 2}}\nseeds: 0-1\ntrials: 2\n"
        "space: {agent.alpha: {low: 0.1, high: 1.0}}\n"
    )
    out = tmp_path / os.fsdecode(b"tune\xfe")
    result = invoke("tune", tune, "--out", out, "--workers", 1, "-q")
    assert result.exit_code == 0, result.output
    header = (out / "best.yaml").read_text(encoding="utf-8").splitlines()[1]
    assert header.endswith("tune\ufffd/best.yaml")


def test_text_that_cannot_be_utf8_is_a_write_error_naming_the_file(tmp_path: Path) -> None:
    path = tmp_path / "notes.yaml"
    with pytest.raises(WriteError, match=r"notes\.yaml: cannot be written: .*not UTF-8"):
        atomic.atomic_write_text(path, "name: " + os.fsdecode(b"\xff"))
    assert list(tmp_path.iterdir()) == []


# -- extensions, defaults, --force ------------------------------------------------------


@pytest.mark.parametrize(
    ("suffix", "magic"), [(".png", b"\x89PNG"), (".svg", b"<?xml"), (".pdf", b"%PDF")]
)
def test_plot_writes_the_format_its_extension_names(
    run_dir: Path, tmp_path: Path, suffix: str, magic: bytes
) -> None:
    for extra in ((), ("--policy",)):
        out = tmp_path / f"figure{len(extra)}{suffix.upper()}"
        result = invoke("plot", run_dir, *extra, "--out", out)
        assert result.exit_code == 0, result.output
        assert out.read_bytes().startswith(magic)


def test_unsupported_extensions_are_refused(run_dir: Path, tmp_path: Path, no_play: None) -> None:
    _refused(invoke("plot", run_dir, "--out", tmp_path / "p.jpg"), ".jpg", ".png, .svg, .pdf")
    _refused(invoke("plot", run_dir, "--out", tmp_path / "p"), "without an extension")
    _refused(invoke("eval", run_dir, "--video", tmp_path / "v.avi"), ".avi", ".gif, .mp4")
    assert list(tmp_path.iterdir()) == []


def test_mp4_without_an_encoder_says_what_to_install(
    run_dir: Path, tmp_path: Path, no_play: None
) -> None:
    if importlib.util.find_spec("imageio_ffmpeg") is not None:
        pytest.skip("imageio-ffmpeg is installed")
    _refused(invoke("eval", run_dir, "--video", tmp_path / "v.mp4"), "v.mp4", "imageio-ffmpeg")


def test_existing_files_are_kept_without_force(run_dir: Path, tmp_path: Path) -> None:
    png, gif = tmp_path / "p.png", tmp_path / "v.gif"
    png.write_bytes(b"mine")
    gif.write_bytes(b"mine")
    _refused(invoke("plot", run_dir, "--out", png), str(png), "already exists", "--force")
    _refused(invoke("eval", run_dir, "--video", gif), str(gif), "already exists", "--force")
    assert png.read_bytes() == gif.read_bytes() == b"mine"
    assert invoke("plot", run_dir, "--out", png, "--force").exit_code == 0
    assert png.read_bytes().startswith(b"\x89PNG")
    result = invoke("eval", run_dir, "--episodes", "1", "--video", gif, "--force")
    assert result.exit_code == 0
    assert gif.read_bytes().startswith(b"GIF8")


def test_plot_writes_into_the_run_directory_by_default(
    run_dir: Path, tmp_path: Path, in_tmp: Path
) -> None:
    run = tmp_path / "copy"
    shutil.copytree(run_dir, run)
    (run / "reward_curve.png").unlink()
    result = invoke("plot", run)
    # the figure training draws, under the same name, redrawn in place
    assert result.exit_code == 0 and result.stdout.strip() == str(run / "reward_curve.png")
    assert (run / "reward_curve.png").is_file()
    assert invoke("plot", run).exit_code == 0
    result = invoke("plot", run, "--policy")
    assert result.exit_code == 0 and result.stdout.strip() == str(run / "policy_map.png")
    assert invoke("plot", run, "--policy").exit_code == 0
    # an explicit --out is never replaced without --force
    _refused(invoke("plot", run, "--out", run / "policy_map.png"), "already exists")
    # several runs: the current directory
    result = invoke("plot", run, run_dir)
    assert result.exit_code == 0 and result.stdout.strip() == "reward_curves.png"
    assert (in_tmp / "reward_curves.png").is_file()


# -- --render needs a display that answers ----------------------------------------------


def test_render_with_an_unreachable_display_is_refused(
    run_dir: Path, monkeypatch: pytest.MonkeyPatch, no_play: None
) -> None:
    assert not Path("/tmp/.X11-unix/X99").exists()
    monkeypatch.setenv("DISPLAY", ":99")
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    _refused(invoke("eval", run_dir, "--render"), "--render needs a display", "DISPLAY=:99")
    monkeypatch.setenv("DISPLAY", "127.0.0.1:99.0")
    _refused(invoke("eval", run_dir, "--render"), "127.0.0.1, port 6099")
    monkeypatch.setenv("DISPLAY", "nonsense")
    _refused(invoke("eval", run_dir, "--render"), "not an X display name")


@pytest.fixture
def fake_x_server(monkeypatch: pytest.MonkeyPatch) -> Iterator[str]:
    """A TCP socket where an X server would listen, as DISPLAY=127.0.0.1:n."""
    server = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    for number in range(50, 400):
        try:
            server.bind(("127.0.0.1", 6000 + number))
        except OSError:
            continue
        break
    else:
        pytest.skip("no free port for a fake X server")
    server.listen(4)
    monkeypatch.setenv("DISPLAY", f"127.0.0.1:{number}")
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    try:
        yield f"127.0.0.1:{number}"
    finally:
        server.close()


def test_a_display_that_answers_is_accepted(
    fake_x_server: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.delenv("SDL_VIDEODRIVER", raising=False)
    assert display_problem() is None


def test_render_refuses_pygames_invisible_drivers(
    run_dir: Path, fake_x_server: str, monkeypatch: pytest.MonkeyPatch, no_play: None
) -> None:
    monkeypatch.setenv("SDL_VIDEODRIVER", "dummy")
    _refused(invoke("eval", run_dir, "--render"), "SDL_VIDEODRIVER=dummy")


def test_recording_a_video_does_not_leave_the_dummy_driver_set(
    run_dir: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import cartpole_q.store.video

    monkeypatch.delenv("SDL_VIDEODRIVER", raising=False)
    importlib.reload(cartpole_q.store.video)  # as if imported for the first time
    result = invoke("eval", run_dir, "--episodes", "1", "--video", tmp_path / "v.gif")
    assert result.exit_code == 0, result.output
    assert "SDL_VIDEODRIVER" not in os.environ
