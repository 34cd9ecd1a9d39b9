"""The 3D view's Qt-free core: robot model profiles and their kinematics, the camera
(projection, picking, preset views, fit-all), reachability, and the plan's dry-run timeline."""
