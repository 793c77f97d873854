"""Failures named, early: every one as users meet it, through the ``screwkit`` command.

Each refusal is exactly one line on stderr (``Error: ...``) naming the file, element, chain or
option, with exit status 1 and no traceback or warning; refusals of outputs and of huge maps
come before any computation (a map states its size on stderr before it starts: the refusal is
the only line) and leave no file behind. The command runs in a subprocess with ``-W error``
(``helpers.screwkit``); its time limit only guards against a hang.
"""

from __future__ import annotations

import json
import math
import os
import re
import shutil
import subprocess
import sys
import xml.etree.ElementTree as ElementTree
from pathlib import Path

import numpy as np
import pytest

from helpers import in_millimetres, one_line_error, screwkit
from screwkit.closure import UnreachablePose, solve, solve_one
from screwkit.closure.solve import MISSES_CLOSURE, OUTSIDE_LIMITS
from screwkit.io.loader import bundled_path, load
from screwkit.model.urdf_reader import MAX_FILE_BYTES, MAX_LINKS, MAX_TREE_DEPTH
from screwkit.model.urdf_writer import planar_rrr_urdf
from screwkit.studies.maps import MAX_CONFIGURATIONS, MapSize, disc_grid, disc_size, map_size, planar_disc_map
from screwkit.studies.tasks import Execution

SLOW_MAP = ("map", "planar_5rrr", "--radius", "0.6", "--step", "0.005", "--phi-step", "1")
"""A map of 16 million configurations: about 20 s of computation on a 2-core machine."""


def bundled_text(name: str) -> str:
    return bundled_path(name).read_text(encoding="utf-8")


def write(path: Path, text: str) -> Path:
    path.write_text(text, encoding="utf-8")
    return path


def add_before_end(text: str, extra: str) -> str:
    assert text.count("</robot>") == 1
    return text.replace("</robot>", extra + "</robot>")


def joint_block(text: str, name: str) -> str:
    match = re.search(rf'  <joint name="{name}" type="[a-z]+">.*?</joint>\n', text, flags=re.S)
    assert match, name
    return match.group(0)


# -- the tree -----------------------------------------------------------------------------------


def test_a_cycle_in_the_tree_is_named(tmp_path):
    """a -> l -> a: chain_1's first link hangs from its own second link."""
    text = bundled_text("planar_5rrr")
    block = joint_block(text, "chain_1_joint_b")
    cyclic = text.replace(block, block.replace('<parent link="base_link" />', '<parent link="chain_1_link_l" />'))
    path = write(tmp_path / "cycle.urdf", cyclic)
    one_line_error(screwkit("info", path), str(path), "cycle",
                   "chain_1_link_a (chain_1_joint_b) -> chain_1_link_l (chain_1_joint_c) -> chain_1_link_a")
    with pytest.raises(ValueError, match="cycle of links"):
        load(path)


def test_a_cycle_through_the_base_link_is_named(tmp_path):
    text = add_before_end(bundled_text("planar_5rrr"), '  <joint name="back_to_base" type="fixed">\n'
                          '    <parent link="chain_1_link_a" />\n    <child link="base_link" />\n  </joint>\n')
    path = write(tmp_path / "base_cycle.urdf", text)
    one_line_error(screwkit("analyze", path), str(path), "<joint name='back_to_base'>",
                   "base_link (back_to_base) -> chain_1_link_a (chain_1_joint_b) -> base_link")


def test_a_link_with_two_parents_is_named(tmp_path):
    text = add_before_end(bundled_text("planar_5rrr"), '  <joint name="second_parent" type="fixed">\n'
                          '    <parent link="chain_2_link_a" />\n    <child link="chain_1_link_l" />\n  </joint>\n')
    path = write(tmp_path / "two_parents.urdf", text)
    line = one_line_error(screwkit("info", path), str(path), "<link name='chain_1_link_l'>", "two parents",
                          "'chain_1_joint_c'", "'second_parent'")
    assert "valid URDF model" not in line  # not Pinocchio's message, which names nothing


def test_fewer_actuators_than_dof_is_said_by_the_loader(tmp_path):
    text = re.sub(r'  <transmission name="chain_[345]_joint_b_transmission">.*?</transmission>\n', "",
                  bundled_text("planar_5rrr"), flags=re.S)
    assert text.count("<transmission") == 2
    path = write(tmp_path / "underactuated.urdf", text)
    needles = (str(path), "2 actuator(s)", "chain_1:chain_1_joint_b", "chain_2:chain_2_joint_b", "3 DOF")
    one_line_error(screwkit("info", path), *needles)
    with pytest.raises(ValueError) as raised:
        load(path)
    assert all(needle in str(raised.value) for needle in needles)


def test_a_zero_axis_is_accepted_on_a_fixed_joint(tmp_path):
    """CAD exporters write <axis xyz="0 0 0"/> on every fixed joint: it means nothing there."""
    text = add_before_end(bundled_text("planar_5rrr"),
                          '  <link name="marker" />\n  <joint name="marker_joint" type="fixed">\n'
                          '    <parent link="platform" />\n    <child link="marker" />\n'
                          '    <origin xyz="0 0 0.1" rpy="0 0 0" />\n    <axis xyz="0 0 0" />\n  </joint>\n')
    path = write(tmp_path / "fixed_zero_axis.urdf", text)
    with_marker = screwkit("analyze", path, "--pose", "paper_fig_2a", "--json")
    assert with_marker.returncode == 0 and with_marker.stderr == "", with_marker.stderr
    bundled = screwkit("analyze", "planar_5rrr", "--pose", "paper_fig_2a", "--json")
    assert json.loads(with_marker.stdout) == json.loads(bundled.stdout)


@pytest.mark.parametrize("mechanism, joint, joint_type", [
    ("planar_5rrr", "chain_1_joint_c", "continuous"),
    ("planar_5rrr", "chain_1_joint_c", "revolute"),
    ("ups_hexapod_8", "leg_1_joint_slider", "prismatic"),
])
def test_a_zero_axis_is_refused_where_it_matters(tmp_path, mechanism, joint, joint_type):
    text = bundled_text(mechanism)
    block = joint_block(text, joint)
    changed = re.sub(r'<axis xyz="[^"]*" />', '<axis xyz="0 0 0" />', block)
    changed = re.sub(r'type="[a-z]+"', f'type="{joint_type}"', changed, count=1)
    if joint_type == "revolute" and "<limit" not in changed:
        limit = '    <limit lower="-3" upper="3" effort="1" velocity="1" />\n'
        changed = changed.replace("  </joint>", limit + "  </joint>")
    path = write(tmp_path / "zero_axis.urdf", text.replace(block, changed))
    one_line_error(screwkit("info", path), str(path), f"<joint name='{joint}'><axis>", "zero vector")


def deep_chain(count: int) -> str:
    """planar_5rrr with a chain of ``count`` fixed links hanging from the platform."""
    extra = "".join(f'  <link name="extra_{i}" />\n  <joint name="extra_joint_{i}" type="fixed"><parent link='
                    f'"{"platform" if i == 0 else f"extra_{i - 1}"}" /><child link="extra_{i}" /></joint>\n'
                    for i in range(count))
    return add_before_end(bundled_text("planar_5rrr"), extra)


def test_a_tree_too_deep_for_pinocchio_is_refused_instead_of_crashing(tmp_path):
    """Pinocchio's parser recurses once per level: 5,000 levels crashed the process (SIGSEGV)."""
    path = write(tmp_path / "deep.urdf", deep_chain(5000))
    one_line_error(screwkit("info", path), str(path), f"more than the {MAX_TREE_DEPTH} levels", "MAX_TREE_DEPTH")
    allowed = write(tmp_path / "allowed.urdf", deep_chain(MAX_TREE_DEPTH - 1))  # the platform is one level down
    assert screwkit("info", allowed).returncode == 0


# -- unreachable poses ---------------------------------------------------------------------------

FOUR_BASE = np.array([[1.0, 0.0], [0.0, 1.0], [-1.0, 0.0], [0.0, -1.0]])
FOUR_PLATFORM = 0.1 * FOUR_BASE
STRETCHED = float(np.hypot(1.4, 0.45)) / 2
"""Arm length with which chain 3 is exactly stretched at the pose (0.5, 0.45, 0)."""


def four_rrr(tmp_path: Path, proximal, distal) -> Path:
    return write(tmp_path / "planar_4rrr.urdf",
                 planar_rrr_urdf("planar_4rrr", FOUR_BASE, FOUR_PLATFORM, proximal, distal))


def misses(pose, proximal, distal) -> np.ndarray:
    """By how far each R-R-R chain misses its closure: |d - b| outside [|a - l|, a + l] (0 if inside)."""
    x, y, phi = pose
    rotation = np.array([[math.cos(phi), -math.sin(phi)], [math.sin(phi), math.cos(phi)]])
    distance = np.linalg.norm(np.array([x, y]) + FOUR_PLATFORM @ rotation.T - FOUR_BASE, axis=-1)
    proximal, distal = np.broadcast_to(proximal, 4), np.broadcast_to(distal, 4)
    return np.maximum.reduce([distance - (proximal + distal), np.abs(proximal - distal) - distance, np.zeros(4)])


@pytest.mark.parametrize("pose, proximal, distal", [
    # chains 3 and 4 miss, by different amounts
    ((0.5, 0.45, 0.0), 0.7, 0.7),
    # chain 3 exactly stretched (degenerate: it misses by 0 or by a rounding error), chain 4 misses by 0.04 m
    ((0.5, 0.45, 0.0), [0.7, 0.7, STRETCHED, 0.7], [0.7, 0.7, STRETCHED, 0.7]),
    # three chains miss, one of them (chain 2) by being too close to its base joint, with the platform turned
    ((0.32, 1.12, math.radians(60)), 0.5, 1.0),
])
def test_an_unreachable_pose_names_the_chain_that_misses_most_first(tmp_path, pose, proximal, distal):
    path = four_rrr(tmp_path, proximal, distal)
    expected = misses(pose, proximal, distal)
    real = [int(c) for c in np.argsort(-expected) if expected[c] > 1e-9]
    assert real, "the pose must be unreachable"
    shown = [f"{pose[0]:g}", f"{pose[1]:g}", f"{math.degrees(pose[2]):g}"]
    line = one_line_error(screwkit("analyze", path, "--pose", *shown), str("planar_4rrr"), "is unreachable")
    named = re.findall(r"chain '(chain_\d)' misses closure by ([0-9.e+-]+) m", line)
    assert [int(name[-1]) - 1 for name, _ in named[:len(real)]] == real, line  # the worst first
    for name, amount in named:
        assert float(amount) == pytest.approx(expected[int(name[-1]) - 1], abs=1e-6), line
    for name, _ in named[len(real):]:  # a degenerate chain may follow, never lead
        assert expected[int(name[-1]) - 1] < 1e-9
    # The same through the Python API: solve_one raises the same message; solve says why per chain.
    mechanism = load(path)
    solution = solve(mechanism, np.array(pose))
    np.testing.assert_allclose(np.where(solution.status == MISSES_CLOSURE, solution.residuals, 0.0), expected,
                               atol=1e-12)
    assert set(np.flatnonzero(solution.status == MISSES_CLOSURE)) >= set(real)
    with pytest.raises(UnreachablePose) as raised:
        solve_one(mechanism, np.array(pose))
    assert line == f"Error: {raised.value}"


# -- joint limits --------------------------------------------------------------------------------


def slider_leg(text: str) -> dict:
    """Leg 1 of the UPS hexapod from its URDF: base point, platform point, leg offset, slider limits."""
    root = ElementTree.fromstring(text)
    joints = {joint.get("name"): joint for joint in root.findall("joint")}
    loop = next(loop for loop in root.findall("loop") if loop.get("chain") == "leg_1")
    limit = joints["leg_1_joint_slider"].find("limit")

    def xyz(element):
        return np.array([float(v) for v in element.find("origin").get("xyz").split()])

    return {"base": xyz(joints["leg_1_joint_u1"]), "platform": xyz(loop.find("successor")),
            "offset": float(xyz(loop.find("predecessor"))[0]),
            "limits": (float(limit.get("lower")), float(limit.get("upper")))}


def test_a_joint_just_past_its_limit_is_shown_with_the_digits_that_tell_it_from_the_limit():
    """The hexapod raised until leg 1's slider is 1e-8 m past its upper limit (beyond LIMIT_SLACK, within which it
    would be at the limit): the message used to show both to 6 digits, the value equal to the limit it is said to be
    outside of; it now shows as many digits as tell them apart, and the number shown is past the limit."""
    leg = slider_leg(bundled_text("ups_hexapod_8"))
    upper = leg["limits"][1]
    d = leg["platform"] - leg["base"]
    z = math.sqrt((upper + leg["offset"] + 1e-8) ** 2 - d[0] ** 2 - d[1] ** 2) - d[2]
    with pytest.raises(UnreachablePose) as caught:
        solve_one(load("ups_hexapod_8"), [0, 0, z, 0, 0, 0])
    shown = re.search(r"joint 'leg_1_joint_slider' at (\S+) m is outside its limits \[(\S+), (\S+)\]",
                      str(caught.value))
    assert shown, str(caught.value)
    assert shown.group(1) != shown.group(3) and float(shown.group(1)) > upper, shown.group(0)


def test_joint_limits_make_a_pose_unreachable_and_ignore_limits_lifts_them():
    """The hexapod 'reached' z = 50 m with its slider at 48.9 m, against an upper limit of 0.894 m."""
    leg = slider_leg(bundled_text("ups_hexapod_8"))
    slider = float(np.linalg.norm(leg["platform"] + [0, 0, 50] - leg["base"])) - leg["offset"]
    line = one_line_error(screwkit("analyze", "ups_hexapod_8", "--pose", "0", "0", "50", "0", "0", "0"),
                          "'ups_hexapod_8'", "chain 'leg_1': joint 'leg_1_joint_slider'",
                          f"at {slider:.6g} m is outside its limits [{leg['limits'][0]:.6g}, {leg['limits'][1]:.6g}]")
    assert line.index("leg_1_joint_slider") < line.index("leg_2_joint_slider")
    geometric = screwkit("analyze", "ups_hexapod_8", "--pose", "0", "0", "50", "0", "0", "0", "--ignore-limits",
                         "--json")
    assert geometric.returncode == 0 and geometric.stderr == "", geometric.stderr
    assert json.loads(geometric.stdout)["reachable"] is True
    # Python: the reason is in the solution (status per chain, the joint outside its limits).
    mechanism = load("ups_hexapod_8")
    solution = solve(mechanism, [0, 0, 50, 0, 0, 0])
    assert not solution.reachable and np.all(solution.status == OUTSIDE_LIMITS)
    chain = mechanism.chains[0]
    assert chain.joint_names[int(solution.limit_joints[0])] == "leg_1_joint_slider"
    assert solve(mechanism, [0, 0, 50, 0, 0, 0], limits=False).reachable


def test_continuous_joints_have_no_limits():
    for chain in load("planar_5rrr").chains:
        assert np.all(np.isinf(chain.joint_limits))


@pytest.mark.parametrize("mechanism, pose", [
    ("ups_hexapod_8", "home"),
    ("ups_hexapod_8", "0.05 -0.03 1.1 4 -3 10"),
    ("planar_5rrr", "paper_fig_2a"),
    ("coop_arms", "home"),
    ("delta_4", "off_centre"),  # lower mobility: poses in task coordinates (x y z; z roll pitch; x y z yaw)
    ("prs_3_ups", "0.2 10 -5"),
    ("schoenflies_5", "shifted_turned"),
])
def test_indices_at_reachable_poses_do_not_depend_on_limits(mechanism, pose):
    within = screwkit("analyze", mechanism, "--pose", *pose.split(), "--json")
    ignoring = screwkit("analyze", mechanism, "--pose", *pose.split(), "--json", "--ignore-limits")
    assert within.returncode == 0 and ignoring.returncode == 0, within.stdout + within.stderr
    assert json.loads(within.stdout) == json.loads(ignoring.stdout)


# -- huge inputs ---------------------------------------------------------------------------------


def test_a_map_too_large_for_memory_is_refused_before_it_starts_with_its_size(tmp_path):
    """--step 1e-5 once died allocating 107 GiB; --step 1e-4 started without a word and grew past 9.7 GB.
    The refusal is the only line: the map never stated its size, which it does before it starts."""
    out = tmp_path / "huge.nc"
    result = screwkit("map", "planar_5rrr", "--radius", "0.6", "--step", "1e-5", "--out", out, timeout=120)
    line = one_line_error(result, "configurations", "grid points", "360 orientations", "GiB", "coarser grid")
    assert not out.exists()
    stated = int(re.search(r"([0-9,]+) configurations", line).group(1).replace(",", ""))
    assert stated == pytest.approx(math.pi * (0.6 / 1e-5) ** 2 * 360, rel=1e-3)  # pi r^2 / step^2 points x 360
    # Proceeding does not lift a refusal for memory.
    one_line_error(screwkit("map", "planar_5rrr", "--radius", "0.6", "--step", "1e-5", "--yes", timeout=120), "GiB")


def test_a_map_above_the_configuration_limit_needs_yes(tmp_path):
    out = tmp_path / "large.nc"
    result = screwkit("map", "planar_5rrr", "--radius", "0.6", "--step", "1e-4", "--out", out, timeout=120)
    line = one_line_error(result, f"more than {MAX_CONFIGURATIONS:,}", "--yes")
    assert not out.exists()
    stated = int(re.search(r"([0-9,]+) configurations", line).group(1).replace(",", ""))
    assert stated > MAX_CONFIGURATIONS


def test_map_sizes_are_known_before_allocating_and_checked():
    five = load("planar_5rrr")
    # The stated size is the grid's own (small enough to build here).
    x, y, mask = disc_grid(0.3, 0.05, (0.0, 0.0))
    size = disc_size(five, 0.3, 0.05, 30.0)
    assert size.grid_points == int(mask.sum()) and size.orientations == 12
    assert size.grid_shape == mask.shape and size.configurations == 12 * int(mask.sum())
    assert map_size(five, {"x": x, "y": y}, {"phi": np.arange(12)}, mask) == size
    # Above a configuration limit: refused unless told to proceed.
    with pytest.raises(ValueError, match=r"more than 100; .*pass --yes to proceed"):
        size.check(max_configurations=100, available_bytes=2**40)
    size.check(max_configurations=100, proceed=True, available_bytes=2**40)
    with pytest.raises(ValueError, match=r"pass --yes"):
        planar_disc_map(five, 0.3, 0.05, 30.0, max_configurations=100, execution=Execution(progress=False))
    small = planar_disc_map(five, 0.3, 0.05, 30.0, max_configurations=100, proceed=True,
                            execution=Execution(progress=False))
    assert small.attrs["configurations"] == size.configurations
    # Memory: the result must fit, whatever `proceed` says.
    needed = size.memory_bytes
    assert needed == mask.size * (8 * size.variables + 1) + 8 * sum(mask.shape)
    for proceed in (False, True):
        with pytest.raises(ValueError, match=r"its result alone needs .* more than this machine can give"):
            size.check(proceed=proceed, available_bytes=needed)
    size.check(available_bytes=2 * needed)
    huge = MapSize(grid_points=10**12, orientations=360, variables=7, grid_shape=(10**6, 10**6))
    with pytest.raises(ValueError) as raised:
        huge.check(available_bytes=2**34)
    assert "360,000,000,000,000 configurations" in str(raised.value)
    assert f"needs {huge.memory_bytes / 2**30:.1f} GiB" in str(raised.value)
    assert "(16.0 GiB available)" in str(raised.value)


def peak_memory(arguments) -> tuple[int, int]:
    """(exit status, peak resident memory in KiB) of a screwkit command."""
    with open(os.devnull, "w") as sink:
        process = subprocess.Popen([sys.executable, "-W", "error", "-m", "screwkit.cli", *map(str, arguments)],
                                   stdout=sink, stderr=sink)
        _, status, usage = os.wait4(process.pid, 0)
        process.returncode = os.waitstatus_to_exitcode(status)
    return process.returncode, usage.ru_maxrss


def test_map_memory_does_not_grow_with_the_number_of_configurations(tmp_path):
    """8 times the orientations (1.4 million configurations) in the memory of the smaller map."""
    common = ("map", "planar_5rrr", "--radius", "0.3", "--step", "0.01", "--task-size", "20000", "--quiet")
    small_status, small = peak_memory(common + ("--phi-step", "4", "--out", tmp_path / "small.nc"))
    large_status, large = peak_memory(common + ("--phi-step", "0.5", "--out", tmp_path / "large.nc"))
    assert small_status == large_status == 0
    assert large < 1.25 * small, (small, large)


def minimal_links(count: int) -> str:
    extra = "".join(f'<link name="e{i}"/><joint name="j{i}" type="fixed"><parent link="platform"/>'
                    f'<child link="e{i}"/></joint>\n' for i in range(count))
    return add_before_end(bundled_text("planar_5rrr"), extra)


def test_a_file_over_the_size_cap_is_refused_unread(tmp_path):
    """A 50 MB URDF of 189,081 links was read for 35 minutes."""
    big = write(tmp_path / "big.urdf", minimal_links(160_000))
    assert big.stat().st_size > MAX_FILE_BYTES
    one_line_error(screwkit("info", big), str(big), f"{big.stat().st_size:,} bytes", f"{MAX_FILE_BYTES:,}",
                   "MAX_FILE_BYTES")
    # Refused before reading: a sparse 4 GiB file (zeros, not XML) is refused for its size, not as bad XML.
    sparse = tmp_path / "sparse.urdf"
    with open(sparse, "wb") as handle:
        handle.truncate(4 * 2**30)
    one_line_error(screwkit("info", sparse, timeout=120), str(sparse), f"{4 * 2**30:,} bytes")


def test_a_file_with_too_many_links_is_refused_before_pinocchio_builds_it(tmp_path):
    """Pinocchio's model building grows with the square of the links: 148,000 took 8.5 min."""
    path = write(tmp_path / "many.urdf", minimal_links(MAX_LINKS))
    one_line_error(screwkit("info", path), str(path), f"{MAX_LINKS + 12:,} links", f"more than the {MAX_LINKS:,}",
                   "MAX_LINKS")


def test_the_largest_file_allowed_loads(tmp_path):
    """Pinocchio included (how the reading time grows with the file: benchmarks/bench_reading.py)."""
    largest = write(tmp_path / "largest.urdf", minimal_links(MAX_LINKS - 12))
    result = screwkit("info", largest, "--json")
    assert result.returncode == 0, result.stderr
    assert json.loads(result.stdout)["mechanism"] == "planar_5rrr"


# -- outputs -------------------------------------------------------------------------------------


def assert_refused_early(result, folder: Path, *needles: str, before: set | None = None) -> None:
    one_line_error(result, *needles)  # the only line: the map did not start (it states its size first)
    after = set(os.listdir(folder)) if folder.is_dir() else set()
    assert after == (before or set()), after  # nothing written, no temporary file left


@pytest.mark.parametrize("name, problem", [
    ("missing/map.nc", "does not exist"),
    ("map.txt", "the --out file must end in .nc, .csv"),
])
def test_a_bad_output_is_refused_before_the_computation(tmp_path, name, problem):
    out = tmp_path / name
    result = screwkit(*SLOW_MAP, "--out", out, timeout=120)
    assert_refused_early(result, tmp_path, f"--out {out}", problem)


def test_a_bad_figure_suffix_is_refused_before_the_computation(tmp_path):
    figure = tmp_path / "map.jpg"
    result = screwkit(*SLOW_MAP, "--out", tmp_path / "map.nc", "--figure", figure, timeout=120)
    assert_refused_early(result, tmp_path, f"--figure {figure}", ".png, .pdf, .svg")


def test_an_output_that_is_a_folder_is_refused(tmp_path):
    (tmp_path / "map.nc").mkdir()
    result = screwkit(*SLOW_MAP, "--out", tmp_path / "map.nc", timeout=120)
    assert_refused_early(result, tmp_path, str(tmp_path / "map.nc"), "is a directory", "--help",
                         before={"map.nc"})


@pytest.fixture
def unwritable_folder(tmp_path):
    """A folder no file can be created in: mode 555, or for root (whom modes do not stop) immutable."""
    folder = tmp_path / "read-only"
    folder.mkdir()
    if os.geteuid() != 0:
        folder.chmod(0o555)
        yield folder
        folder.chmod(0o755)
        return
    chattr = shutil.which("chattr")
    if chattr is None or subprocess.run([chattr, "+i", folder], capture_output=True).returncode != 0:
        pytest.skip("running as root, for whom a mode-555 folder stays writable, and `chattr +i` is unavailable")
    try:
        yield folder
    finally:
        subprocess.run([chattr, "-i", folder], check=True)


def test_a_read_only_folder_is_refused_before_the_computation(unwritable_folder):
    out = unwritable_folder / "map.nc"
    result = screwkit(*SLOW_MAP, "--out", out, timeout=120)
    assert_refused_early(result, unwritable_folder, f"--out {out}", "cannot write in the folder")


def test_a_folder_that_takes_no_files_is_refused_before_the_computation():
    """/proc takes no new files, although os.access says it is writable for root."""
    result = screwkit(*SLOW_MAP, "--out", "/proc/map.nc", timeout=120)
    one_line_error(result, "--out /proc/map.nc", "cannot write in the folder /proc")


def test_an_existing_output_is_replaced_only_with_overwrite(tmp_path):
    out = tmp_path / "map.nc"
    out.write_bytes(b"earlier result")
    result = screwkit(*SLOW_MAP, "--out", out, timeout=120)
    assert_refused_early(result, tmp_path, f"--out {out}", "the file exists; pass --overwrite",
                         before={"map.nc"})
    assert out.read_bytes() == b"earlier result"
    replaced = screwkit("map", "planar_5rrr", "--radius", "0.2", "--step", "0.1", "--phi-step", "30", "--out", out,
                        "--overwrite", "--quiet")
    assert replaced.returncode == 0 and replaced.stderr == ""
    assert out.read_bytes().startswith(b"CDF") and sorted(os.listdir(tmp_path)) == ["map.nc"]


def test_a_read_only_existing_output_is_kept_even_with_overwrite(tmp_path):
    out = tmp_path / "map.nc"
    out.write_bytes(b"protected")
    out.chmod(0o444)
    result = screwkit(*SLOW_MAP, "--out", out, "--overwrite", timeout=120)
    assert_refused_early(result, tmp_path, f"--out {out}", "read-only", before={"map.nc"})
    assert out.read_bytes() == b"protected"


def dead_pid() -> int:
    child = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True, text=True)
    return int(child.stdout)


def test_temporary_files_of_killed_runs_are_removed_and_named(tmp_path):
    out = tmp_path / "sweep.nc"
    stale = tmp_path / f".sweep.nc.tmp-{dead_pid()}-1764000000000000000"
    live = tmp_path / f".sweep.nc.tmp-{os.getpid()}-1764000000000000001"  # a write under way: kept
    stale.write_bytes(b"half a file")
    live.write_bytes(b"being written")
    result = screwkit("sweep", "planar_5rrr", "--phi", "0:360:90", "--out", out)
    assert result.returncode == 0, result.stderr
    assert f"removed {stale}: temporary file(s) left by an earlier run killed while writing {out}" in result.stderr
    assert not stale.exists() and live.exists() and out.exists()


@pytest.mark.parametrize("arguments", [
    ("map", "planar_5rrr", "--radius", "0.3", "--step", "0.1", "--phi-step", "400"),
    ("map", "planar_5rrr", "--radius", "0.3", "--step", "0.1", "--phi-step", "0"),
    ("design-search", "permutations", "planar_5rrr", "--phi-step", "400"),
    ("design-search", "family", "planar_rrr", "--phi-step", "400"),
])
def test_a_phi_step_beyond_a_turn_is_refused(arguments):
    one_line_error(screwkit(*arguments), "Expected 0 < --phi-step <= 360 (deg)")


# -- units ---------------------------------------------------------------------------------------


@pytest.mark.parametrize("mechanism, poses", [
    ("planar_5rrr", ["paper_fig_2a", "0.1 -0.05 20"]),
    ("ups_hexapod_8", ["home", "0.05 -0.03 1.1 4 -3 10"]),
    ("schoenflies_5", ["shifted_turned"]),  # lower mobility (x y z yaw), a prismatic limit scaled
])
def test_a_file_in_millimetres_gives_the_indices_of_the_file_in_metres(tmp_path, mechanism, poses):
    path = write(tmp_path / f"{mechanism}_mm.urdf", in_millimetres(bundled_text(mechanism)))
    for pose in poses:
        metres = json.loads(screwkit("analyze", mechanism, "--pose", *pose.split(), "--json").stdout)
        result = screwkit("analyze", path, "--length-unit", "mm", "--pose", *pose.split(), "--json")
        assert result.returncode == 0, result.stdout
        millimetres = json.loads(result.stdout)
        for key in ("iti", "lmti"):
            assert millimetres[key] == pytest.approx(metres[key], abs=1e-12)
        for key in ("f_o", "f_io", "iti_actuators", "pose"):
            assert millimetres[key] == pytest.approx(metres[key], abs=1e-12), key
        assert millimetres["worst_faults"] == metres["worst_faults"]
    described = json.loads(screwkit("info", path, "--length-unit", "mm", "--json").stdout)
    assert described["length_unit"] == "mm"
    expected = json.loads(screwkit("info", mechanism, "--json").stdout)["named_poses"]
    assert described["named_poses"].keys() == expected.keys()
    for name, pose in expected.items():
        assert described["named_poses"][name] == pytest.approx(pose, abs=1e-12)


# -- every command, warnings as errors -----------------------------------------------------------

EVERY_COMMAND = {
    "list": ("list",),
    "info": ("info", "ups_hexapod_8"),
    "analyze": ("analyze", "planar_5rrr", "--pose", "paper_fig_2a"),
    "verify": ("verify", "planar_5rrr", "--samples", "20"),
    "sweep": ("sweep", "planar_5rrr", "--phi", "0:360:30", "--out", "{tmp}/sweep.nc"),
    "map": ("map", "planar_5rrr", "--radius", "0.2", "--step", "0.1", "--phi-step", "30", "--out", "{tmp}/map.nc"),
    "map-spatial": ("map", "ups_hexapod_8", "--grid", "x:-0.02:0.02:0.02", "--grid", "y:-0.02:0.02:0.02",
                    "--over", "yaw:0:360:90"),
    "design-search-permutations": ("design-search", "permutations", "planar_5rrr", "--phi-step", "30"),
    "design-search-optimise": ("design-search", "optimise", "planar_5rrr", "--maxiter", "1", "--popsize", "2",
                               "--step", "0.2", "--urdf", "{tmp}/best.urdf"),
    "view": ("view", "planar_5rrr", "--html", "{tmp}/view.html"),
}


@pytest.mark.parametrize("arguments", EVERY_COMMAND.values(), ids=EVERY_COMMAND.keys())
def test_every_command_runs_without_a_warning(tmp_path, arguments):
    result = screwkit(*(str(a).format(tmp=tmp_path) for a in arguments))
    assert result.returncode == 0, result.stderr
    assert "Warning" not in result.stderr and "Traceback" not in result.stderr, result.stderr


UNREACHABLE = {
    "analyze": (("analyze", "{four}", "--pose", "0.5", "0.5", "0"), 1),
    "analyze-limits": (("analyze", "ups_hexapod_8", "--pose", "0", "0", "50", "0", "0", "0"), 1),
    "view": (("view", "planar_5rrr", "--pose", "3", "3", "0", "--html", "{tmp}/view.html"), 1),
    "sweep": (("sweep", "{four}", "--at", "0.5", "0.5", "--phi", "0:360:30"), 0),
    "map-spatial": (("map", "ups_hexapod_8", "--grid", "x:-0.02:0.02:0.02", "--grid", "y:-0.02:0.02:0.02",
                     "--over", "yaw:0:360:90", "--at", "0", "0", "50", "0", "0", "0"), 0),
    "map-planar": (("map", "{four}", "--radius", "0.8", "--step", "0.2", "--phi-step", "30"), 0),
}


@pytest.mark.parametrize("arguments, status", UNREACHABLE.values(), ids=UNREACHABLE.keys())
def test_unreachable_poses_give_no_warning(tmp_path, arguments, status):
    four = four_rrr(tmp_path, 0.7, 0.7)
    result = screwkit(*(str(a).format(tmp=tmp_path, four=four) for a in arguments))
    assert result.returncode == status, result.stderr
    assert "Warning" not in result.stderr and "Traceback" not in result.stderr, result.stderr
    if status:
        one_line_error(result, "is unreachable")
