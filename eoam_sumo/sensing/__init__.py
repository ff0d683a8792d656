"""Sensing and perception models: friction belief, automotive radar, tracker."""
