"""Facts that must have one value everywhere they are written down.

Where a fact cannot be read from one definition (ROS needs literals in ``package.xml`` and whole
``.msg`` files), these tests check the copies against the definition.
"""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest
from mcap.reader import make_reader

import hexapod_workspace
from hexapod_workspace import logs
from hexapod_workspace._version import __version__
from hexapod_workspace.core.base import params
from hexapod_workspace.logs import interfaces, messages
from hexapod_workspace.logs.writer import LIBRARY, LogWriter

ROOT = Path(__file__).resolve().parents[1]
MSG_DEFS = ROOT / "msg_defs"


def test_one_version_everywhere():
    assert hexapod_workspace.__version__ == __version__
    assert re.fullmatch(r"\d+\.\d+\.\d+", __version__)
    for package_xml in (ROOT / "package.xml", MSG_DEFS / "package.xml"):
        version = ET.parse(package_xml).getroot().findtext("version")
        assert version == __version__, package_xml
    # setup.py reads _version.py; what it finds is what pip installed (editable install)
    from importlib.metadata import version

    assert version("hexapod_workspace") == __version__


def test_the_mcap_library_string_names_the_versions(tmp_path):
    from importlib.metadata import version

    assert f"hexapod_workspace {__version__}; mcap {version('mcap')}" == LIBRARY
    path = tmp_path / "a.mcap"
    with LogWriter(path) as writer:
        writer.write_fields(
            messages.TOPICS["workspace_request"],
            messages.TYPES["workspace_request"],
            messages.workspace_request_fields(0, [0.0, 0.0, -1.3]),
            1,
        )
    with path.open("rb") as handle:
        assert make_reader(handle).get_header().library == LIBRARY


def test_one_node_name_and_one_interface_table():
    assert interfaces.NODE_NAME is params.NODE_NAME
    keys = [row.key for row in interfaces.INTERFACES]
    assert len(keys) == len(set(keys))
    for row in interfaces.INTERFACES:
        assert row.kind in {"publisher", "subscription", "service", "action"}, row
        assert row.name.startswith("/"), row
        if not row.key.startswith("/"):
            assert interfaces.relative_name(row.key) == f"~/{row.key}"
            assert row.name == f"/{params.NODE_NAME}/{row.key}"
    assert set(messages.TOPICS) <= set(keys)
    with pytest.raises(KeyError, match="no_such"):
        interfaces.interface("no_such")


def _fields(text: str) -> list[str]:
    """Definition lines without comments, whitespace collapsed (what the type is made of)."""
    lines = (line.split("#", 1)[0].strip() for line in text.splitlines())
    return [" ".join(line.split()) for line in lines if line]


def _twins() -> list[tuple[str, str, Path]]:
    """(service part, its text, the message twin's file) for every .srv of the package."""
    found = []
    for srv in sorted((MSG_DEFS / "srv").glob("*.srv")):
        request, response = srv.read_text(encoding="utf-8").split("\n---\n")
        for part, text in (("Request", request), ("Response", response)):
            found.append((f"{srv.stem}_{part}", text, MSG_DEFS / "msg" / f"{srv.stem}{part}.msg"))
    return found


@pytest.mark.parametrize("part, text, twin", _twins(), ids=lambda v: getattr(v, "name", None))
def test_message_twins_match_their_service_parts(part, text, twin):
    """The logs record a service call as the message twins of its parts (logs.typestore): each
    twin has exactly the fields of its part, in order (so the very CDR bytes)."""
    assert twin.is_file(), f"{part}: no message twin {twin.relative_to(ROOT)}"
    assert _fields(twin.read_text(encoding="utf-8")) == _fields(text), part


def test_every_message_twin_has_its_service():
    twins = {path.name for _, _, path in _twins()}
    for path in (MSG_DEFS / "msg").glob("*.msg"):
        if not path.read_text(encoding="utf-8").startswith("# The recorded form of a"):
            continue  # not a twin
        stem = re.sub(r"(Request|Response)$", "", path.stem)
        if path.name == "TriggerResponse.msg":  # std_srvs/srv/Trigger's response
            definition = logs.message_definition("std_srvs/srv/Trigger_Response")
            assert _fields(path.read_text(encoding="utf-8")) == _fields(definition)
            continue
        assert path.name in twins, f"{path.name}: no service {stem}.srv to be the twin of"


def test_the_declared_licence_is_the_one_shipped():
    text = (ROOT / "LICENSE").read_text(encoding="utf-8")
    assert "Apache License" in text and "Version 2.0, January 2004" in text
    assert "END OF TERMS AND CONDITIONS" in text  # the whole text, not a pointer to it
    for package_xml in (ROOT / "package.xml", MSG_DEFS / "package.xml"):
        assert ET.parse(package_xml).getroot().findtext("license") == "Apache-2.0"
    from importlib.metadata import metadata

    assert metadata("hexapod_workspace")["License"] == "Apache-2.0"
