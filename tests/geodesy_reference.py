"""Reference points of the UTM local grid shared by the geodesy and navigation tests.

Origin Forest Lake (43.8253, -70.3304, zone 19T, MOOS-IvP's and the course's examples); each (x, y) -> (lat, lon)
was computed independently with pyproj/PROJ and a port of MOOS's Gantz code.
"""

ORIGIN = (43.8253, -70.3304)
REFERENCE = [
    ((0.0, -20.0), (43.82511997, -70.33039600)),
    ((60.0, -40.0), (43.82494863, -70.32964602)),
    ((180.0, -100.0), (43.82442590, -70.32814209)),
    ((100.0, 100.0), (43.82621460, -70.32917667)),
    ((1000.0, -1000.0), (43.81644267, -70.31776886)),
]
