"""Bundled mechanisms of screwkit (URDF files following ``docs/urdf-convention.md``).

Load them by name with :func:`screwkit.io.loader.load`; list them with
:func:`screwkit.io.loader.bundled_names`. Their documented poses are ``<named_pose>`` elements of
the files (``load(name).named_poses``). The files are generated from parameters by
``python -m screwkit.robots.generate``; their geometry is documented in ``README.md`` here.
"""
