// URDFs that cannot be imported, and the URDF items misused.

// Not well-formed XML: its file:line:column.
moreau::model! {
    pub struct Malformed;
    urdf = "tests/ui/yaml/malformed.urdf";
}

// A URDF that does not exist; a constraint naming one of its bodies.
moreau::model! {
    pub struct Missing;
    urdf = "tests/ui/yaml/no_such_robot.urdf";
    constraints { floor: position_z(hand) + 1 >= 0 }
    restitution = 0.5;
}

// A URDF outside the crate.
moreau::model! {
    pub struct Outside;
    urdf = "/etc/passwd";
}

// `locked` and `limits` without a URDF.
moreau::model! {
    pub struct NoUrdf;
    coordinates { x: vx }
    kinetic = 0.5 * vx^2;
    locked { shoulder }
    limits { elbow }
}

// Malformed items: a path that is not a string, joint lists not in braces,
// a name that is not a joint name.
moreau::model! {
    pub struct Shapes;
    urdf = tests / robot;
    locked = [shoulder];
    limits { elbow, 3 }
}

// A URDF with no links, and one whose joints leave no root.
moreau::model! {
    pub struct Empty;
    urdf = "tests/ui/yaml/empty.urdf";
}

moreau::model! {
    pub struct Cycle;
    urdf = "tests/ui/yaml/cycle.urdf";
}

// The URDF named before the model's name.
moreau::model!(urdf = "tests/ui/yaml/two_joints.urdf");

fn main() {}
