moreau::model! {
    pub struct Ball;
    coordinates { y: vy }
    kinetic = 0.5 * vy^2;
    constraints { floor: y >= 0, #[restitution = -0.2] ceiling: y <= 2 }
    restitution = 1.5;
}

fn main() {}
