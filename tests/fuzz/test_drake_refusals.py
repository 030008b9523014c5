"""What Drake refuses with an assertion reaches the user as one line.

pydrake raises a failed ``DRAKE_DEMAND`` ("Failure at ...") as
``SystemExit``: no ``except Exception`` catches it.  A fuzzer found two:
a model whose sphere has a radius of NaN (``plan``: Drake's bare text, no
``drakegrasp: error:``), and a subnormal load (``analyze --load
1e-310,0,0,0,0,0``: the payload program's column divided by the load's
size overflowed to inf, which Drake's LinearConstraint refused).
"""

from __future__ import annotations

import pytest

import drakegrasp as dg
from drakegrasp.cli import main

NAN_SPHERE = """<?xml version="1.0"?>
<sdf version="1.9">
  <model name="ball">
    <link name="ball">
      <inertial><mass>0.1</mass></inertial>
      <collision name="c"><geometry><sphere><radius>nan</radius></sphere>
      </geometry></collision>
    </link>
  </model>
</sdf>
"""


def test_a_shape_drake_refuses_is_one_line(tmp_path, capsys):
    model = tmp_path / "nan_ball.sdf"
    model.write_text(NAN_SPHERE)
    assert main(["plan", str(model), "--num", "5"]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1
    assert err[0].startswith("drakegrasp: error: ") and "radius" in err[0]
    with pytest.raises(dg.ModelError, match="radius"):  # not SystemExit
        dg.planning_scene(
            str(model), hand_url="package://drakegrasp/hands/parallel_jaw.sdf"
        )


def test_a_subnormal_load_is_analysed(capsys):
    assert main(["analyze", "three_finger_sphere", "--load", "1e-310,0,0,0,0,0"]) == 0
    out = capsys.readouterr().out
    assert "payload" in out or "holds" in out
