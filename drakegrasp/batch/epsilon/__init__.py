"""Ferrari–Canny L1 ε of many grasps.

The driver, the compiled expanding-polytope kernel and its polytope updates.
"""
