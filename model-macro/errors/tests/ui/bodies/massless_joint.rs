// A joint that moves no mass or inertia (a massless link, as some URDFs
// have: Romeo's hands) leaves a zero on the diagonal of `M`: refused,
// naming the joint's coordinate.
moreau::model! {
    pub struct Massless;
    bodies {
        arm: { joint: revolute(shoulder), axis: [0, 0, 1], mass: 1, com: [0.5, 0, 0] },
        hand: { parent: arm, joint: revolute(wrist), axis: [0, 0, 1], xyz: [1, 0, 0], mass: 0 },
    }
    restitution = 0.5;
}

fn main() {}
