"""rigid_dynamics/wheelset."""
