"""Paper B: Mars powered descent, vision-aided inertial EKF, landmark selection."""
