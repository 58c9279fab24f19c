"""REP 2011 type hashes (RIHS01) of every message type agrisim knows, computed by agrisim-msgs
(src/type_hash.rs), against rosbags' independent implementation (Typestore.hash_rihs01):

* over types registered from our own .msg files (every type, agrisim_msgs included);
* over rosbags' bundled ROS 2 Jazzy definitions, for every standard type Jazzy has: equal
  hashes mean our .msg files are Jazzy's, so a Jazzy peer accepts our type hashes.
"""

import json
import os
import shutil
import subprocess
from pathlib import Path

import pytest
from rosbags import typesys

REPO = Path(__file__).resolve().parent.parent
MSG_DIR = REPO / "models" / "msgs"

def _hashes_cmd() -> list[str]:
    exe = os.environ.get("AGRISIM_MSGS_TYPE_HASHES")
    if exe:
        return [exe]
    built = REPO / "target" / "release" / "examples" / "type_hashes"
    if built.exists():
        return [str(built)]
    if shutil.which("cargo") is None:
        pytest.fail("neither target/release/examples/type_hashes nor cargo found")
    return ["cargo", "run", "-q", "--release", "-p", "agrisim-msgs", "--example", "type_hashes"]


@pytest.fixture(scope="module")
def ours() -> dict[str, str]:
    out = subprocess.run(_hashes_cmd(), cwd=REPO, check=True, capture_output=True, text=True).stdout
    return json.loads(out)


def msg_files() -> dict[str, str]:
    return {f"{p.parts[-3]}/msg/{p.stem}": p.read_text() for p in sorted(MSG_DIR.glob("*/msg/*.msg"))}


def test_every_msg_file_has_a_hash(ours):
    assert sorted(ours) == sorted(msg_files())
    assert all(h.startswith("RIHS01_") and len(h) == 71 for h in ours.values())


def test_hashes_equal_rosbags_over_our_definitions(ours):
    store = typesys.get_typestore(typesys.Stores.EMPTY)
    for name, text in msg_files().items():
        store.register(typesys.get_types_from_msg(text, name))
    wrong = {t: (h, store.hash_rihs01(t)) for t, h in ours.items() if store.hash_rihs01(t) != h}
    assert not wrong, wrong


def test_standard_types_hash_as_in_jazzy(ours):
    jazzy = typesys.get_typestore(typesys.Stores.ROS2_JAZZY)
    compared = 0
    wrong = {}
    for t, h in ours.items():
        if t.startswith("agrisim_msgs/") or t not in jazzy.fielddefs:
            continue
        compared += 1
        if jazzy.hash_rihs01(t) != h:
            wrong[t] = (h, jazzy.hash_rihs01(t))
    assert not wrong, wrong
    # Every standard type but those of packages outside ros2/common_interfaces, which
    # rosbags does not bundle (vision_msgs, control_msgs).
    missing = sorted(t for t in ours if not t.startswith(("agrisim_msgs/", "vision_msgs/", "control_msgs/")) and t not in jazzy.fielddefs)
    assert not missing, missing
    assert compared >= 40, compared


def test_a_changed_definition_changes_the_hash(ours):
    """The comparison can fail: one field renamed gives rosbags another hash."""
    store = typesys.get_typestore(typesys.Stores.EMPTY)
    files = msg_files()
    files["std_msgs/msg/String"] = files["std_msgs/msg/String"].replace("data", "text")
    for name, text in files.items():
        store.register(typesys.get_types_from_msg(text, name))
    assert store.hash_rihs01("std_msgs/msg/String") != ours["std_msgs/msg/String"]
