"""Paper A: EM-EKF camera optical-axis bias estimation on Mars approach."""
