"""uvnav's laws as a ROS 2 node, with no ROS installation: the ROS 2 messages as Cyclone DDS
types (:mod:`uvnav.ros2.msgs`), their conversion to what a law reads
(:mod:`uvnav.ros2.convert`), the decisions (:mod:`uvnav.ros2.navigator`), the DDS node
(:mod:`uvnav.ros2.node`) and the laws' parameters as ROS 2 parameters
(:mod:`uvnav.ros2.params`).

Every module but :mod:`uvnav.ros2.params` needs the ``cyclonedds`` package (the ``ros2``
extra); this package imports none of them.
"""
