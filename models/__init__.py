"""Hand, object and scene models shipped with drakegrasp (data only).

Installed as the package ``drakegrasp.models``; ``package.xml`` names the ROS-style
package ``drakegrasp`` so that ``package://drakegrasp/...`` URIs resolve once
:func:`drakegrasp.register_models` has been called on a parser or package map.
"""
