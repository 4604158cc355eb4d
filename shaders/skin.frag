#version 460
// skin.frag - flat shading from screen-space derivatives: skinned meshes carry no skinned
// normals in the benchmark, and the fragment cost stays the same for every vertex format.

layout(location = 0) in vec3 world_position;
layout(location = 0) out vec4 color;

void main()
{
    vec3 normal = normalize(cross(dFdx(world_position), dFdy(world_position)));
    float light = 0.25 + 0.75 * abs(dot(normal, normalize(vec3(0.3, 0.8, 0.5))));
    color = vec4(vec3(light), 1.0);
}
