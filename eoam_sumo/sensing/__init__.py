"""Sensing and perception models: friction belief, automotive radar, tracker, V2X messages
and what is known of the next lane."""
