"""Run-time layout of a wall: an integer kind and a float64 parameter row.

Every wall the case defines (planes, rectangles, boxes, cylinders) becomes one or more rows of
``WALL_WIDTH`` float64 values, so that the contact kernel can loop over walls with an integer
switch. A box becomes six (or five, if open) rectangles with inward normals.

Columns (unused ones are zero):

=========  ===========================================================================
columns    meaning
=========  ===========================================================================
0:3        ``point``: a point of the plane / the rectangle centre / a point on the axis
3:6        ``normal`` (plane, rectangle; unit, towards the particles) or ``axis`` (cylinder)
6:9        translational velocity of the wall [m/s]
9:12       rectangle: in-plane unit axis ``u`` (the other axis is ``v = normal x u``)
12         rectangle: half extent along u; cylinder: radius [m]
13         rectangle: half extent along v; cylinder: half length along the axis (inf = none)
14         cylinder: +1 particles inside, -1 particles outside
15         cylinder: angular velocity about the axis [rad/s] (right hand rule)
16         material index of the wall
17         thermal condition: 0 adiabatic, 1 fixed temperature
18         wall temperature [K] (current value when the condition is a function of time)
19         reserved
=========  ===========================================================================
"""

WALL_WIDTH = 20

PLANE = 0
RECTANGLE = 1
CYLINDER = 2

COL_POINT = 0
COL_NORMAL = 3
COL_AXIS = 3
COL_VELOCITY = 6
COL_U = 9
COL_HALF_U = 12
COL_RADIUS = 12
COL_HALF_V = 13
COL_HALF_LENGTH = 13
COL_SIDE = 14
COL_OMEGA = 15
COL_MATERIAL = 16
COL_THERMAL_KIND = 17
COL_TEMPERATURE = 18

KIND_NAMES = {PLANE: "plane", RECTANGLE: "rectangle", CYLINDER: "cylinder"}
