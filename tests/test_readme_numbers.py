"""Numbers the docs pages print from a run are the committed run's (tools/readme.py writes them)."""

import importlib.util
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
spec = importlib.util.spec_from_file_location("readme_tool", ROOT / "tools" / "readme.py")
readme_tool = importlib.util.module_from_spec(spec)
spec.loader.exec_module(readme_tool)


def test_every_generated_block_is_what_its_artefact_gives():
    for document in readme_tool.DOCUMENTS:
        text = document.read_text(encoding="utf-8")
        for name, body in readme_tool.blocks(document).items():
            assert readme_tool.current(text, name) == body, (
                f"{document.name} block '{name}' differs from its artefact: "
                "run .venv/bin/python tools/readme.py")


def test_the_check_sees_a_changed_number():
    text = readme_tool.RESULTS.read_text(encoding="utf-8")
    body = readme_tool.blocks()["validation"]
    changed = text.replace(body, body.replace("checks passed", "checks passed!"))
    assert readme_tool.current(changed, "validation") != body


def test_the_results_atlas_table_is_the_reports():
    table = readme_tool.blocks()["stability-table"]
    assert table in (ROOT / "docs" / "stability.md").read_text(encoding="utf-8")


def test_the_results_page_counts_the_atlas_axes():
    data = readme_tool.stability.load()
    words = {8: "eight"}
    assert f"{words[len(data['axes'])]} sweeps" in readme_tool.RESULTS.read_text(encoding="utf-8")


def test_a_finding_the_atlas_no_longer_shows_stops_the_tool():
    import copy

    import pytest

    stability = readme_tool.stability
    data = stability.load()
    assert stability.tables(data)  # the committed run shows every finding
    grown = copy.deepcopy(data)
    for row in grown["rows"]:
        if row["method"] == "uzawa" and row["status"] == "diverged":
            row["message"] = "diverged: λ grew by 1e6"  # "growth is never seen" is then false
    with pytest.raises(stability.StaleFinding, match="two-step cycle"):
        stability.tables(grown)


def test_the_one_door_reading_quotes_the_committed_speed_run():
    """Every ratio the reading under the speed table quotes is one the committed run gives."""
    import re

    text = readme_tool.ONE_DOOR.read_text(encoding="utf-8")
    table = readme_tool.blocks(readme_tool.ONE_DOOR)["one-door-speed"]
    reading = text[text.index("**Reading (the committed run"):]
    reading = reading.split("\n\n")[0].split(").**", 1)[1]  # the command's own numbers left out
    quoted = re.findall(r"\b\d\.\d\d\b", reading)
    assert len(quoted) >= 8
    for number in quoted:
        assert number in table, f"docs/one-door.md's reading quotes {number}, which its run lacks"
