"""What the driver and the road do, independent of any model: steer inputs, paths, drivers."""
