"""The ground truth the sensors see and the verdict judges: every road user as a body with its
oriented box (``bodies``), the boxes' geometry and contact (``geometry``), and the lane bands
and motion thresholds that give a road user its role (``lanes``). No SUMO, no sensing."""
