// Joints that mimic another, from a URDF and written by hand, where they
// cannot: every problem at once, each where it is written.
moreau::model! {
    pub struct Mimics;
    urdf = "tests/ui/yaml/mimics.urdf";
    locked { held }
    restitution = 0.5;
}

moreau::model! {
    pub struct Hand;
    bodies {
        a: { joint: revolute(q1), axis: [0, 0, 1], mass: 1 },
        // a joint that mimics has no coordinate of its own
        b: { parent: a, joint: revolute(q2), mimic: q1, axis: [0, 0, 1], mass: 1 },
        // a fixed joint does not move
        c: { parent: a, joint: fixed, mimic: q1, mass: 1 },
        // the multiplier of a joint that mimics nothing
        d: { parent: a, joint: revolute(q3), multiplier: 2, axis: [0, 0, 1], mass: 1 },
        // a name that is no coordinate
        e: { parent: a, joint: revolute, mimic: a, axis: [0, 0, 1], mass: 1 },
    }
    restitution = 0.5;
}

fn main() {}
