"""Physical validation of certified grasps: do they hold an object in a physics engine?
"""
