"""An OBJ file as (vertices, triangles) arrays, polygons fanned, for the comparison scripts."""

import numpy as np


def read_obj(path):
    points, triangles = [], []
    with open(path) as f:
        for line in f:
            words = line.split()
            if words and words[0] == "v":
                points.append([float(x) for x in words[1:4]])
            elif words and words[0] == "f":
                corners = [int(w.split("/")[0]) for w in words[1:]]
                corners = [c - 1 if c > 0 else len(points) + c for c in corners]
                triangles += [[corners[0], a, b] for a, b in zip(corners[1:], corners[2:])]
    return np.array(points), np.array(triangles, dtype=np.int64)
