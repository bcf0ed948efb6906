"""A validation suite's checks as CI systems read them: JUnit XML and GitHub Actions annotations.

JUnit XML follows the schema CI systems validate against (Jenkins' xunit
``junit-10.xsd``, read by GitHub, GitLab and Jenkins alike): one
``<testsuite>`` per case, one ``<testcase>`` per check, a ``<failure>`` for a
check that failed. GitHub Actions turns ``::error file=…,title=…::message``
lines on standard output into annotations
(https://docs.github.com/actions/reference/workflow-commands-for-github-actions).
"""

from __future__ import annotations

import io
import math
import re
import xml.etree.ElementTree as ET
from typing import Any, Mapping

__all__ = ["check_message", "github_annotations", "junit_xml"]

#: characters XML 1.0 cannot hold (control characters other than tab, newline, return)
_NOT_XML = re.compile("[\x00-\x08\x0b\x0c\x0e-\x1f\ufffe\uffff]")


def check_message(check: Any) -> str:
    """One line saying why ``check`` failed: its value against its limit, and its detail."""
    if check.limit is None:
        said = "failed"
    elif isinstance(check.value, float) and not math.isfinite(check.value):
        said = f"no value to hold to the limit {check.limit:g}"
    else:
        said = f"{check.value:.3g} is over the limit {check.limit:g}"
    return f"{said}: {check.detail}" if check.detail else said


def _text(value: Any) -> str:
    return _NOT_XML.sub("?", str(value))


def _seconds(value: float) -> str:
    return f"{value:.3f}" if math.isfinite(value) and value >= 0 else "0"


def junit_xml(suite: Any, files: Mapping[str, str] | None = None) -> str:
    """The suite's checks as a JUnit XML document (``<testsuites>``), encoded text.

    ``suite`` is a :class:`signorini.studies.suite.SuiteResult`; ``files``
    maps a case's name to the problem file it came from (the ``file``
    attribute of its ``<testsuite>``).
    """
    files = files or {}
    failed = sum(not c.passed for c in suite.checks)
    root = ET.Element("testsuites", name="signorini validate", tests=str(len(suite.checks)),
                      failures=str(failed), errors="0", time=_seconds(suite.elapsed_s))
    for result in suite.results:
        name = result.case.name
        checks = [c for c in suite.checks if c.case == name]
        spent = sum(r.get("time_s", 0.0) for r in result.runs
                    if isinstance(r.get("time_s"), float) and math.isfinite(r["time_s"]))
        attributes = {"name": _text(name), "tests": str(len(checks)),
                      "failures": str(sum(not c.passed for c in checks)), "errors": "0",
                      "skipped": "0", "time": _seconds(spent)}
        if name in files:
            attributes["file"] = _text(files[name])
        element = ET.SubElement(root, "testsuite", attributes)
        properties = ET.SubElement(element, "properties")
        for key, value in (("scene", result.case.scene), ("dofs", result.problem.n),
                           ("contact candidates", result.problem.m)):
            ET.SubElement(properties, "property", name=key, value=_text(value))
        for check in checks:
            case = ET.SubElement(element, "testcase", name=_text(check.name),
                                 classname=_text(f"validate.{name}"))
            if not check.passed:
                message = _text(check_message(check))
                failure = ET.SubElement(case, "failure", type="check", message=message)
                failure.text = message
    buffer = io.BytesIO()
    ET.ElementTree(root).write(buffer, encoding="utf-8", xml_declaration=True)
    return buffer.getvalue().decode("utf-8") + "\n"


def _escape(text: str, in_property: bool = False) -> str:
    """GitHub's escaping of a workflow command's data (and, for properties, ``:`` and ``,``)."""
    text = str(text).replace("%", "%25").replace("\r", "%0D").replace("\n", "%0A")
    return text.replace(":", "%3A").replace(",", "%2C") if in_property else text


def github_annotations(suite: Any, files: Mapping[str, str] | None = None) -> list[str]:
    """One ``::error`` line per failed check; ``file=`` names the case's problem file, if any."""
    files = files or {}
    lines = []
    for check in suite.checks:
        if check.passed:
            continue
        properties = [f"title={_escape(f'{check.case}: {check.name}', True)}"]
        if check.case in files:
            properties.insert(0, f"file={_escape(files[check.case], True)}")
        lines.append(f"::error {','.join(properties)}::{_escape(check_message(check))}")
    return lines
