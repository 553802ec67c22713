"""ROS 2 launch file for gnss_ins_node.

    ros2 launch launch_scripts/gnss_ins_node.launch.py \
        params_file:=params/ermakf.yaml namespace:=/robot imu_topic:=/sensors/imu

Arguments: params_file (default: params/ekf.yaml next to this directory), namespace,
node_name, imu_topic, gnss_topic, fix_topic (remappings of the node's relative inputs
imu, gnss/measurements and gnss/fix), odometry_topic, log_level.
The node must be installed as executable gnss_ins_node of package adaptive_gnss_ins.
"""

import os

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node

PACKAGE_ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DEFAULT_PARAMS = os.path.join(PACKAGE_ROOT, 'params', 'ekf.yaml')


def generate_launch_description():
    arguments = [
        DeclareLaunchArgument('params_file', default_value=DEFAULT_PARAMS,
                              description='ROS 2 parameter file (a preset of params/)'),
        DeclareLaunchArgument('namespace', default_value='',
                              description='namespace of the node and its topics'),
        DeclareLaunchArgument('node_name', default_value='gnss_ins_node',
                              description='node name (the params file key must match or be /**)'),
        DeclareLaunchArgument('imu_topic', default_value='imu'),
        DeclareLaunchArgument('gnss_topic', default_value='gnss/measurements'),
        DeclareLaunchArgument('fix_topic', default_value='gnss/fix'),
        DeclareLaunchArgument('odometry_topic', default_value='odometry'),
        DeclareLaunchArgument('log_level', default_value='info'),
    ]
    node = Node(
        package='adaptive_gnss_ins',
        executable='gnss_ins_node',
        name=LaunchConfiguration('node_name'),
        namespace=LaunchConfiguration('namespace'),
        parameters=[LaunchConfiguration('params_file')],
        remappings=[
            ('imu', LaunchConfiguration('imu_topic')),
            ('gnss/measurements', LaunchConfiguration('gnss_topic')),
            ('gnss/fix', LaunchConfiguration('fix_topic')),
            ('odometry', LaunchConfiguration('odometry_topic')),
        ],
        arguments=['--ros-args', '--log-level', LaunchConfiguration('log_level')],
        output='screen',
    )
    return LaunchDescription(arguments + [node])
