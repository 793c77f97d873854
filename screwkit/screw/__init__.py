"""The screw algebra and what it builds: chain screws, motion spaces, point outputs, constraint wrenches and the
CTI, planar mechanisms by hand, and the plain-numpy reference of the whole index pipeline.
"""
