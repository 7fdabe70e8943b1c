"""A state's verdict under the sphere filter: its spheres touch nothing; unsure; a hull or table pair surely collides.

Shared by the filter and its compiled kernels, which the filter imports only when first built.
"""

CLEAR, MAYBE, COLLIDES = 1, 0, -1
