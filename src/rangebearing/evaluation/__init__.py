"""Judging readings against ground truth: truth files, matching, calibration fits, annotated frames.

Nothing here runs on the robot's hot path; the daemon never imports it.
"""
