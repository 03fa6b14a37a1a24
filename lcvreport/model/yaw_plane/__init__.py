"""The yaw-plane model of the thesis, ``M x' = S x + F``: its equations, states, outputs and loads."""
