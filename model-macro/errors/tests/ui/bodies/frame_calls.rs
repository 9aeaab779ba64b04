// Body-frame calls with mistakes: a direction without its three
// coordinates, a point with two, and a direction of something not a body.
moreau::model! {
    pub struct BadFrameCalls;
    parameters { k: 1.0 }
    bodies {
        arm: { parent: world, joint: revolute(q), axis: [0, 0, 1], mass: 1 },
    }
    constraints {
        tilt: direction_z(arm) + 0.5 >= 0,
        reach: 1 - position_x(arm, 1, 0) >= 0,
        other: direction_x(k, 1, 0, 0) + 1 >= 0,
    }
    restitution = 0.5;
}

fn main() {}
