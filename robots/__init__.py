"""Bundled mechanisms of screwkit (URDF files following ``docs/urdf-convention.md``).

Load them by name with :func:`screwkit.mechanism.load`; list them with
:func:`screwkit.mechanism.bundled_names`. The files are generated from parameters by
``python -m screwkit.robots.generate``; their geometry is documented in ``README.md`` here.
"""

NAMED_POSES = {
    "planar_5rrr": {
        "home": (0.0, 0.0, 0.0),
        # The configuration of the paper's Fig. 2(a).
        "paper_fig_2a": (-0.2, 0.0, 0.7853981633974483),
    },
    "planar_4rpr": {
        "home": (0.0, 0.0, 0.0),
        # Leg lines 1, 2, 3 meet in one point here (actuator 4 is then not a mutual-interference
        # actuator); computed by screwkit.robots.generate.four_rpr_concurrent_pose.
        "three_lines_concurrent": (-0.19979756030839574, 0.0, 0.4),
    },
}
"""Documented platform poses (task coordinates, m and rad) of the bundled mechanisms."""
