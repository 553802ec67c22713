"""ROS 2 launch file for gnss_ins_node.

    ros2 launch launch_scripts/gnss_ins_node.launch.py \
        params_file:=params/ermakf.yaml namespace:=/robot imu_topic:=/sensors/imu \
        publish_tf:=true base_frame:=imu_link

Arguments:
- params_file: a parameter file loaded after the manual params/ekf.yaml (which holds
  every parameter at its default): a preset of params/ (they hold only what differs from
  the manual) or a file of your own; default: the manual itself (loaded once).
  namespace, node_name, log_level;
- imu_topic, gnss_topic, fix_topic, velocity_topic, odometry_topic: remappings of the
  node's relative topics imu, gnss/measurements, gnss/fix, gnss/velocity and odometry;
- the node's own parameters use_sim_time (bool), map_frame, base_frame (frame ids),
  publish_tf (bool), queue_depth (int) and imu_frame (a frame id). Their default is ''
  meaning "not set": the value then comes from the params file or, when the file has
  none, from the node's default (false, map, base_link, false, 200, '' = learnt). Choice: a parameters dict given after the
  params file overrides it, so only the arguments the user set are passed; a default that
  is always passed would silently override the params file.
The node must be installed as executable gnss_ins_node of package adaptive_gnss_ins.
"""

import os

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, OpaqueFunction
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node

PACKAGE_ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
# The manual: every parameter at its default; the presets are overlays on it.
MANUAL_PARAMS = os.path.join(PACKAGE_ROOT, 'params', 'ekf.yaml')

# The node's own parameters (src/ros/node/params.rs, NODE_PARAMETERS): name -> (type,
# description). The descriptions name the node's defaults.
NODE_PARAMETERS = {
    'use_sim_time': (bool, 'node time follows /clock (node default: false)'),
    'map_frame': (str, 'frame of the odometry pose and TF parent (node default: map)'),
    'base_frame': (str, 'body frame: odometry child and fix frame (node default: base_link)'),
    'publish_tf': (bool, 'publish map_frame -> base_frame on /tf (node default: false)'),
    'queue_depth': (int, 'history depth of subscriptions and publishers (node default: 200)'),
    'imu_frame': (str, 'the IMU frame_id; others are dropped (node default: learnt)'),
}

# Remapped topics: launch argument -> the node's relative topic name.
TOPIC_REMAPS = {
    'imu_topic': 'imu',
    'gnss_topic': 'gnss/measurements',
    'fix_topic': 'gnss/fix',
    'velocity_topic': 'gnss/velocity',
    'odometry_topic': 'odometry',
}


def _typed(name, kind, text):
    """The launch argument `text` of node parameter `name` as a value of `kind`."""
    if kind is bool:
        if text.lower() in ('true', 'false'):
            return text.lower() == 'true'
        raise ValueError(f'{name} must be true or false, not {text!r}')
    if kind is int:
        try:
            return int(text)
        except ValueError:
            raise ValueError(f'{name} must be an integer, not {text!r}') from None
    return text


def node_parameter_overrides(values):
    """The node parameters the user set, typed: `values` maps each name of
    NODE_PARAMETERS to its launch argument ('' = not set); names left '' are left out, so
    the params file (or the node's default) decides them."""
    return {
        name: _typed(name, kind, values[name])
        for name, (kind, _) in NODE_PARAMETERS.items()
        if values[name] != ''
    }


def _launch_node(context):
    def value(name):
        return LaunchConfiguration(name).perform(context)

    # rcl reads the files in order and a later value wins: the manual, then the preset,
    # then the overrides (launch_ros writes them to a temporary file passed last).
    parameters = [MANUAL_PARAMS]
    params_file = value('params_file')
    if params_file and os.path.abspath(params_file) != MANUAL_PARAMS:
        parameters.append(params_file)
    overrides = node_parameter_overrides({name: value(name) for name in NODE_PARAMETERS})
    if overrides:
        parameters.append(overrides)
    return [Node(
        package='adaptive_gnss_ins',
        executable='gnss_ins_node',
        name=value('node_name'),
        namespace=value('namespace'),
        parameters=parameters,
        remappings=[(topic, value(argument)) for argument, topic in TOPIC_REMAPS.items()],
        arguments=['--ros-args', '--log-level', value('log_level')],
        output='screen',
    )]


def generate_launch_description():
    arguments = [
        DeclareLaunchArgument('params_file', default_value=MANUAL_PARAMS,
                              description='parameter file loaded after params/ekf.yaml (a '
                                          'preset of params/ or your own)'),
        DeclareLaunchArgument('namespace', default_value='',
                              description='namespace of the node and its topics'),
        DeclareLaunchArgument('node_name', default_value='gnss_ins_node',
                              description='node name (the params file key must match or be /**)'),
        DeclareLaunchArgument('log_level', default_value='info'),
    ]
    arguments += [
        DeclareLaunchArgument(argument, default_value=topic,
                              description=f'topic the node\'s {topic} is remapped to')
        for argument, topic in TOPIC_REMAPS.items()
    ]
    arguments += [
        DeclareLaunchArgument(name, default_value='',
                              description=f'{description}; \'\' = not set (params file)')
        for name, (_, description) in NODE_PARAMETERS.items()
    ]
    return LaunchDescription(arguments + [OpaqueFunction(function=_launch_node)])
