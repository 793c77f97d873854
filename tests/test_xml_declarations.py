"""XML declarations as the other tools' parsers take them (screwkit.common.xml_text).

MuJoCo and Gazebo's libsdformat read XML with tinyxml2, which takes a declaration written ``<? xml ...?>`` (a
published Gazebo Stewart platform's first line) or after blank space; Python's parser refused both as not
well-formed XML. MuJoCo's own reading of such an MJCF is the reference that the file is one; the mechanism read is
the one of the file written with a plain declaration (MJCF, SDFormat, URDF), and the rest of a file is still read
as strictly as before."""

from __future__ import annotations

import numpy as np
import pytest
from sdformat_models import upu_sdf
from test_io import HOME, five_bar_mjcf

from helpers import assert_indices_close
from screwkit.common.xml_text import tolerant_declaration
from screwkit.io import ImportError_
from screwkit.io.loader import bundled_path, load
from screwkit.studies.poses import indices_at_pose

DECLARATIONS = ['<? xml version="1.0" ?>\n', '  \n<?xml version="1.0"?>\n', '<?  xml version="1.0" encoding="UTF-8"?>']


@pytest.mark.parametrize("declaration", DECLARATIONS)
def test_an_mjcf_declared_so_is_read_as_mujoco_reads_it(tmp_path, declaration):
    import mujoco

    plain, declared = tmp_path / "plain.xml", tmp_path / "declared.xml"
    plain.write_text(five_bar_mjcf())
    declared.write_text(declaration + five_bar_mjcf())
    reference = mujoco.MjModel.from_xml_string(declared.read_text())  # MuJoCo takes the file as it is
    assert reference.njnt == mujoco.MjModel.from_xml_string(plain.read_text()).njnt
    assert_indices_close(indices_at_pose(load(declared), np.array(HOME)), indices_at_pose(load(plain), np.array(HOME)),
                         1e-12)


@pytest.mark.parametrize("declaration", DECLARATIONS)
def test_sdformat_and_urdf_declared_so_read_as_written_plainly(tmp_path, declaration):
    plain = tmp_path / "plain.sdf"
    plain.write_text(upu_sdf(3))
    declared = tmp_path / "declared.sdf"
    declared.write_text(upu_sdf(3).replace('<?xml version="1.0"?>\n', declaration, 1))
    assert declared.read_text() != plain.read_text()
    pose = load(plain).home_pose + np.array([0.03, -0.02, 0.05])
    assert_indices_close(indices_at_pose(load(declared), pose), indices_at_pose(load(plain), pose), 1e-12)
    urdf = tmp_path / "declared.urdf"
    text = bundled_path("planar_5rrr").read_text()
    urdf.write_text(text.replace('<?xml version="1.0"?>\n', declaration, 1))
    bundled = load("planar_5rrr")
    assert_indices_close(indices_at_pose(load(urdf), bundled.home_pose), indices_at_pose(bundled, bundled.home_pose),
                         1e-12)


def test_only_the_declaration_is_forgiven(tmp_path):
    """A processing instruction that is not a declaration (``<?xmlfoo``) and a malformed body are left to the parser,
    which refuses them in one line naming the file."""
    assert tolerant_declaration(b"<?xmlfoo bar?><a/>") == b"<?xmlfoo bar?><a/>"
    assert tolerant_declaration(b'<? xml version="1.0"?><a/>') == b'<?xml version="1.0"?><a/>'
    broken = tmp_path / "broken.sdf"
    broken.write_text(upu_sdf(3).replace('<?xml version="1.0"?>\n', '<? xml version="1.0" ?>\n', 1)
                      .replace("</model>", "</modle>"))
    with pytest.raises(ImportError_, match=r"broken.sdf: not well-formed XML"):
        load(broken)


def test_convert_writes_back_a_screwkit_urdf_declared_so(tmp_path):
    """`screwkit convert` rewrites a file of screwkit's convention with its reference configuration: a file declared
    `<? xml ...?>` was refused as malformed XML; read now, its rewriting goes through Python's parser too, which
    refused it with a traceback (not even a one-line error) before it was told of the declaration."""
    from helpers import screwkit

    source, out = tmp_path / "declared.urdf", tmp_path / "out.urdf"
    text = bundled_path("planar_5rrr").read_text()
    source.write_text(text.replace('<?xml version="1.0"?>', '<? xml version="1.0" ?>', 1))
    converted = screwkit("convert", source, out)
    assert converted.returncode == 0 and "Traceback" not in converted.stderr, converted.stderr
    bundled = load("planar_5rrr")
    assert_indices_close(indices_at_pose(load(out), bundled.home_pose), indices_at_pose(bundled, bundled.home_pose),
                         1e-12)
