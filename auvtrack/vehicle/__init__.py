"""What a vehicle is: 5-DOF kinematics and kinetics, the packed parameter layout, presets with a source per number."""
