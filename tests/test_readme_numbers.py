"""Numbers the README prints from a run are the committed run's (tools/readme.py writes them)."""

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
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    body = readme_tool.blocks()["validation"]
    changed = text.replace(body, body.replace("checks passed", "checks passed!"))
    assert readme_tool.current(changed, "validation") != body
