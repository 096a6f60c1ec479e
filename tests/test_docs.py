"""The documentation is executed: the tutorials' commands run, their figures are remade, links resolve.

Every fenced ``bash`` block of ``docs/tutorials/*.md`` runs, in page order, in one empty
directory per page, after the page's files (fences with ``title="NAME"``) are written
there. A block that cannot run here is preceded by ``<!-- not run: REASON -->``. The
commands run as printed, on smaller settings: a seed range ``A-B`` becomes ``A-(A+1)`` (two
seeds), and the study files under ``examples/`` are copied with two seeds and a few trials
(the book's, ``examples/book/``, with two values per sweep axis and long runs cut to a
hundredth).
Each figure a tutorial shows must be written by a command printed on its page (its path
from the repository's root, e.g. ``docs/reward_curves.png``), and is, when the page runs.
"""

from __future__ import annotations

import importlib.util
import os
import re
import shutil
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path, PurePosixPath
from types import ModuleType

import pytest
import typer.main
import yaml

from tests.command_server import command_server
from tests.conftest import REPO

DOCS = REPO / "docs"
TUTORIALS = sorted((DOCS / "tutorials").glob("*.md"))

FENCE = re.compile(r"^```(?P<info>[^\n`]*)\n(?P<body>.*?)^```[ \t]*$", re.MULTILINE | re.DOTALL)
NOT_RUN = re.compile(r"<!-- not run: (?P<reason>[^>]*?) -->\s*\Z")
TITLE = re.compile(r'title="(?P<title>[^"]+)"')
IMAGE = re.compile(r"!\[[^\]]*\]\((?P<target>[^)\s]+)\)")

SEED_RANGE = re.compile(r"(?<![\w.:/=-])(?P<low>\d+)-(?P<high>\d+)(?![\w.:/-])")
"""a seed range such as ``0-99`` or ``1000-1099`` (not a date, a path or a number like 1e-4)"""

STUDY_TRIALS = 4
"""trials a tune file keeps in the tests: enough for Optuna's importance plot"""

NOT_RUN_ALLOWED = {"ray-cluster.md": 1}
"""pages that may hold blocks the tests cannot run, and how many (a several-machine cluster)"""


@dataclass(frozen=True)
class Block:
    """One fenced code block of a page."""

    language: str
    title: str | None
    body: str
    not_run: str | None
    """why the tests do not run it, or ``None``"""

    @property
    def runs(self) -> bool:
        """Whether the tests run it: a ``bash`` block that does not say otherwise."""
        return self.language == "bash" and self.not_run is None


def blocks(page: Path) -> list[Block]:
    """The fenced blocks of a page, in order."""
    text = page.read_text(encoding="utf-8")
    found = []
    for match in FENCE.finditer(text):
        info = match["info"].strip()
        language = info.split()[0] if info else ""
        title = TITLE.search(info)
        before = NOT_RUN.search(text[: match.start()])
        reason = before["reason"].strip() if before else None
        found.append(Block(language, title["title"] if title else None, match["body"], reason))
    return found


def shrink(command: str) -> str:
    """The command on small settings: every seed range of more than two seeds cut to two."""

    def two_seeds(match: re.Match[str]) -> str:
        low, high = int(match["low"]), int(match["high"])
        return match[0] if high <= low + 1 else f"{low}-{low + 1}"

    return SEED_RANGE.sub(two_seeds, command)


def shrink_study(path: Path, axes: bool = False) -> None:
    """A sweep or tune file on small settings (comments dropped).

    Two seeds, a few trials, and with ``axes`` each sweep axis cut to its first and last
    values (a zip's axes, and an ``until_optimal`` study's ``scales``, to their first two)
    and runs of over :data:`MOST_EPISODES` episodes (or env steps, ``train.max_env_steps``) to
    a hundredth (:func:`fewer_episodes`):
    the study keeps its shape and its figure, on fewer points and shorter runs (for studies
    whose points no page names by number: the book's).
    """
    data = yaml.safe_load(path.read_text(encoding="utf-8"))
    if not isinstance(data, dict):
        return
    if "seeds" in data:
        data["seeds"] = shrink(str(data["seeds"]))
    if "trials" in data:
        data["trials"] = min(int(data["trials"]), STUDY_TRIALS)
    if axes:
        for key, values in (data.get("grid") or {}).items():
            if isinstance(values, list) and len(values) > 2:
                data["grid"][key] = [values[0], values[-1]]
        for key, values in (data.get("zip") or {}).items():
            if isinstance(values, list):
                data["zip"][key] = values[:2]
        if isinstance(data.get("scales"), list):  # an until_optimal study's maze sizes
            data["scales"] = data["scales"][:2]
        train = (data.get("base") or {}).get("train") or {}
        for key in ("episodes", "max_env_steps"):
            if isinstance(train.get(key), int):
                train[key] = fewer_episodes(train[key])
            for axis in ("grid", "zip"):
                values = (data.get(axis) or {}).get(f"train.{key}")
                if isinstance(values, list):
                    data[axis][f"train.{key}"] = [fewer_episodes(value) for value in values]
    path.write_text(yaml.safe_dump(data, sort_keys=False), encoding="utf-8")


MOST_EPISODES = 1000
"""a book study's runs in the tests: longer ones are cut to a hundredth, at least this many"""


def fewer_episodes(episodes: int) -> int:
    """A book study's episodes in the tests: a hundredth of a long run (the figure's shape)."""
    return episodes if episodes <= MOST_EPISODES else max(MOST_EPISODES, episodes // 100)


def figures(page: Path) -> list[str]:
    """The images a page shows, as paths from the repository's root (``docs/x.png``)."""
    paths = []
    for match in IMAGE.finditer(page.read_text(encoding="utf-8")):
        target = PurePosixPath(page.parent.relative_to(REPO).as_posix()) / match["target"]
        paths.append(os.path.normpath(target.as_posix()))
    return paths


def test_shrink_cuts_seed_ranges_and_nothing_else() -> None:
    assert shrink("train --seeds 0-99 --out runs/C-0-99") == "train --seeds 0-1 --out runs/C-0-99"
    assert shrink("for S in 0-99 1000-1099; do") == "for S in 0-1 1000-1001; do"
    assert shrink("--seeds 0,3,7 --seeds 4-5") == "--seeds 0,3,7 --seeds 4-5"
    assert shrink("# 2026-11-22, kappa 1e-4, length=0.1:1.0:10") == (
        "# 2026-11-22, kappa 1e-4, length=0.1:1.0:10"
    )


def test_shrink_study_keeps_two_seeds_a_few_trials_two_values_per_axis_and_short_runs(
    tmp_path: Path,
) -> None:
    study = tmp_path / "s.yaml"
    study.write_text(
        "# a comment\nbase:\n  train:\n    episodes: 100000\n    max_env_steps: 100000\n"
        "seeds: 0-99\ntrials: 40\n"
        "grid:\n  agent.alpha: [0.1, 0.2, 0.5]\n  agent.n: [1, 2]\n"
        "  train.episodes: [500, 50000, 5000000]\n"
        "zip:\n  agent.lambda: [0, 0.5, 0.9]\n  agent.gamma: [1, 0.9, 0.8]\n",
        encoding="utf-8",
    )
    shrink_study(study, axes=True)
    assert yaml.safe_load(study.read_text(encoding="utf-8")) == {
        "base": {"train": {"episodes": 1000, "max_env_steps": 1000}},
        "seeds": "0-1",
        "trials": STUDY_TRIALS,
        "grid": {"agent.alpha": [0.1, 0.5], "agent.n": [1, 2], "train.episodes": [500, 50000]},
        "zip": {"agent.lambda": [0, 0.5], "agent.gamma": [1, 0.9]},
    }
    runs = (300, 1000, 1001, 99_999, 100_000, 5_000_000)
    assert [fewer_episodes(n) for n in runs] == [300, 1000, 1000, 1000, 1000, 50_000]


def test_blocks_are_found_with_their_titles_and_reasons(tmp_path: Path) -> None:
    page = tmp_path / "page.md"
    page.write_text(
        'text\n\n```bash\necho one\n```\n\n```python title="a.py"\nx = 1\n```\n\n'
        "<!-- not run: needs three machines -->\n```bash\nray start\n```\n",
        encoding="utf-8",
    )
    found = blocks(page)
    assert [(b.language, b.title, b.runs) for b in found] == [
        ("bash", None, True), ("python", "a.py", False), ("bash", None, False),
    ]  # fmt: skip
    assert found[2].not_run == "needs three machines"
    assert found[1].body == "x = 1\n"


def test_every_tutorial_has_commands_and_skips_only_what_it_must() -> None:
    assert len(TUTORIALS) == 8
    for page in TUTORIALS:
        found = blocks(page)
        assert any(block.runs for block in found), f"{page.name} runs no command"
        skipped = [block for block in found if block.not_run is not None]
        assert len(skipped) == NOT_RUN_ALLOWED.get(page.name, 0), page.name
        assert all(block.not_run for block in skipped), f"{page.name}: a skip without a reason"


@pytest.mark.parametrize("page", TUTORIALS, ids=lambda page: page.stem)
def test_every_figure_is_remade_by_the_command_printed_under_it(page: Path) -> None:
    for figure, command in figures_and_commands(page):
        assert (REPO / figure).is_file(), f"{page.name} shows {figure}, which does not exist"
        assert figure in command, f"{page.name}: the command under {figure} does not write it"


def figures_and_commands(page: Path) -> list[tuple[str, str]]:
    """Each figure of a page with the first command block printed under it ("" if none)."""
    text = page.read_text(encoding="utf-8")
    runnable = [
        (match.start(), match["body"])
        for match, block in zip(FENCE.finditer(text), blocks(page), strict=True)
        if block.runs
    ]
    pairs = []
    for match, figure in zip(IMAGE.finditer(text), figures(page), strict=True):
        under = [body for start, body in runnable if start > match.start()]
        pairs.append((figure, under[0] if under else ""))
    return pairs


def _run_page(page: Path, workdir: Path) -> None:
    """Run a page's commands in ``workdir``, as a reader would, on small settings."""
    os.symlink(REPO / "configs", workdir / "configs")
    shutil.copytree(REPO / "examples", workdir / "examples")
    for study in (workdir / "examples").rglob("*.yaml"):
        shrink_study(study, axes=study.parent.name == "book")
    for figure in figures(page):
        (workdir / figure).parent.mkdir(parents=True, exist_ok=True)
    env = {
        **os.environ,
        "PATH": f"{Path(sys.executable).parent}{os.pathsep}{os.environ.get('PATH', '')}",
        "MPLBACKEND": "Agg",
    }
    with command_server(env) as served:
        for block in blocks(page):
            if block.title is not None:
                (workdir / block.title).write_text(block.body, encoding="utf-8")
            if not block.runs:
                continue
            command = shrink(block.body)
            done = subprocess.run(
                ["bash", "-euo", "pipefail", "-c", command],
                cwd=workdir, env=served, capture_output=True, text=True, check=False,
            )  # fmt: skip
            assert done.returncode == 0, (
                f"{page.name}: this block failed (exit {done.returncode}):\n{command}\n"
                f"stdout:\n{done.stdout[-3000:]}\nstderr:\n{done.stderr[-3000:]}"
            )


@pytest.mark.slow
@pytest.mark.parametrize("page", TUTORIALS, ids=lambda page: page.stem)
def test_a_tutorials_commands_run_and_remake_its_figures(page: Path, tmp_path: Path) -> None:
    _run_page(page, tmp_path)
    for figure in figures(page):
        made = tmp_path / figure
        assert made.is_file() and made.stat().st_size > 0, f"{page.name}: {figure} not made"


def _github_anchor(heading: str) -> str:
    """The anchor GitHub gives a Markdown heading."""
    text = re.sub(r"[^\w\- ]", "", heading.strip().lower())
    return text.replace(" ", "-")


def broken_links(markdown: str, root: Path) -> list[str]:
    """The relative links and images of a Markdown text that do not resolve from ``root``.

    A path must exist; an anchor (``#commands``, ``page.md#commands``) must be a heading of
    the text or of the Markdown page it names. Links to the web are not checked (the tests run
    offline), nor links inside code blocks.
    """
    outside_code = re.sub(r"```.*?```", "", markdown, flags=re.DOTALL)
    anchors = _anchors(markdown)
    targets = re.findall(r"\]\(([^)\s]+)\)", outside_code)
    targets += re.findall(r'(?:src|href)="([^"]+)"', outside_code)
    broken = []
    for target in targets:
        if re.match(r"[a-z]+:", target):
            continue
        path, _, anchor = target.partition("#")
        if path and not (root / path).exists():
            broken.append(target)
        elif anchor and path.endswith(".md"):
            if anchor not in _anchors((root / path).read_text(encoding="utf-8")):
                broken.append(target)
        elif anchor and not path and anchor not in anchors:
            broken.append(target)
    return broken


def _anchors(markdown: str) -> set[str]:
    """The anchors of a Markdown text's headings (those outside code blocks)."""
    outside_code = re.sub(r"```.*?```", "", markdown, flags=re.DOTALL)
    return {_github_anchor(h) for h in re.findall(r"^#+ (.+)$", outside_code, re.MULTILINE)}


def test_every_relative_link_of_the_readme_resolves() -> None:
    text = (REPO / "README.md").read_text(encoding="utf-8")
    assert "](docs/" in text  # the check has links to check
    assert broken_links(text, REPO) == []


def test_the_link_check_finds_missing_files_and_anchors() -> None:
    text = (
        "# Title\n## `cartpole-q eval`\n## Sutton & Barto's worlds\n"
        "[a](README.md) [b](docs/nope.md) [c](#cartpole-q-eval) [d](#sutton--bartos-worlds) "
        '[e](#nope) [f](https://example.org/x) <img src="docs/missing.gif">\n'
        "[h](docs/results.md#speed) [i](docs/results.md#nope)\n"
        "```\n[g](in/code.md)\n```\n"
    )
    assert broken_links(text, REPO) == [
        "docs/nope.md", "#nope", "docs/results.md#nope", "docs/missing.gif",
    ]  # fmt: skip


def _hook(name: str) -> ModuleType:
    """A module of ``docs/_hooks`` (they run inside mkdocs, so they are not a package)."""
    spec = importlib.util.spec_from_file_location(name, DOCS / "_hooks" / f"{name}.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_cli_reference_documents_every_command_and_option() -> None:
    from cartpole_q.cli.app import app

    hook = _hook("cli_reference")
    page = hook.on_page_markdown(f"# CLI\n\n{hook.MARKER}\n", page=None)
    assert hook.MARKER not in page and page.startswith("# CLI\n\n## `cartpole-q`\n")
    for command in typer.main.get_command(app).commands:
        assert f"### `cartpole-q {command}`" in page
    assert "* `--set KEY=VALUE`:" in page and "* `--max-steps N`:" in page
    assert '`pip install "cartpole-q[video]"`' in page and "\\[" not in page
    assert hook.on_page_markdown("no marker", page=None) == "no marker"


def test_the_commands_page_has_a_section_for_every_command_naming_its_options() -> None:
    from cartpole_q.cli.app import app

    text = (REPO / "docs" / "commands.md").read_text(encoding="utf-8")
    sections = {
        match["name"]: match["body"]
        for match in re.finditer(r"^## `cartpole-q (?P<name>\w+)`\n(?P<body>.*?)(?=^## |\Z)", text, re.M | re.S)
    }  # fmt: skip
    for name, command in typer.main.get_command(app).commands.items():  # type: ignore[attr-defined]
        assert name in sections, f"docs/commands.md has no section for `cartpole-q {name}`"
        for option in (opt for param in command.params for opt in param.opts):
            if option.startswith("--") and option != "--help":
                assert re.search(rf"(?<![\w-]){option}(?![\w-])", sections[name]), (
                    f"docs/commands.md, `cartpole-q {name}`: {option} is not named"
                )


def test_sphinx_roles_become_code_on_the_api_pages() -> None:
    pytest.importorskip("griffe")  # the docs extra
    plain = _hook("sphinx_roles").plain
    assert plain(":func:`load_config` -- :class:`~cartpole_q.config.Config`, :mod:`x.y`") == (
        "`load_config` -- `Config`, `x.y`"
    )
    assert plain("``literal`` and :unknown:`role`") == "``literal`` and :unknown:`role`"
